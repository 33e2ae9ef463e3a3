// Watertight hits (issue 29): a ray that meets a shared edge or vertex of a mesh, or the rim
// of a closed quadric, hits the surface; it never slips between the triangles or parts.
// Pixel-centre rays of a head-on view fall exactly on the diagonals of quads split in two,
// which is where the gaps showed as black pixels.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "scene/scene.h"
#include "test_scenes.h"

namespace lc::scene {
namespace {

using io::ShapeKind;

// A scene of meshes (and optionally quadrics) with one material and a camera.
struct Builder {
  io::SceneDesc d;
  Builder() { d.materials.emplace_back(); }
  void mesh(std::vector<Vec3> points, std::vector<std::array<int, 3>> tris, const Mat4& m = Mat4::identity()) {
    io::MeshDesc md;
    md.points = std::move(points);
    md.triangles = std::move(tris);
    d.meshes.push_back(std::move(md));
    io::ObjectDesc o;
    o.kind = ShapeKind::Mesh;
    o.mesh = int(d.meshes.size()) - 1;
    o.transform = m;
    d.objects.push_back(o);
  }
  void shape(ShapeKind kind, const Mat4& m) { d.objects.push_back(testing::primitive(kind, m)); }
  // A grid of n x n quads over [-h,h]^2 in the plane z = z0, each split along a diagonal
  // (alternating direction when `alternate`).
  void wall(int n, float h, float z0, bool alternate) {
    std::vector<Vec3> p;
    std::vector<std::array<int, 3>> t;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) p.emplace_back(-h + 2 * h * float(i) / float(n), -h + 2 * h * float(j) / float(n), z0);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, e = a + n + 1;
        if (alternate && (i + j) % 2) {
          t.push_back({a, b, e});
          t.push_back({b, c, e});
        } else {
          t.push_back({a, b, c});
          t.push_back({a, c, e});
        }
      }
    mesh(p, t);
  }
  // A fan of `k` triangles (k a multiple of 4) around the centre of [-h,h]^2 in the plane
  // z = z0: spokes to the corners and to points between them on the square's sides.
  void fan(int k, float h, float z0) {
    std::vector<Vec3> p{Vec3(0, 0, z0)};
    for (int i = 0; i < k; ++i) {
      float a = 2 * kPi * float(i) / float(k) + kPi / 4;  // from a corner: every k covers the square
      // On the square's boundary: scale the unit direction to touch it.
      float c = std::cos(a), s = std::sin(a);
      float r = h / std::max(std::fabs(c), std::fabs(s));
      p.emplace_back(r * c, r * s, z0);
    }
    // Exact spokes where the angle is a multiple of 45 degrees (cos/sin round otherwise).
    for (Vec3& v : p) {
      if (std::fabs(std::fabs(v.x) - h) < 1e-4f * h) v.x = std::copysign(h, v.x);
      if (std::fabs(std::fabs(v.y) - h) < 1e-4f * h) v.y = std::copysign(h, v.y);
      if (std::fabs(v.x) < 1e-4f * h) v.x = 0;
      if (std::fabs(v.y) < 1e-4f * h) v.y = 0;
    }
    std::vector<std::array<int, 3>> t;
    for (int i = 0; i < k; ++i) t.push_back({0, 1 + i, 1 + (i + 1) % k});
    mesh(p, t);
  }
  std::unique_ptr<Scene> build(Vec3 eye, Vec3 view, float fov) {
    d.camera.position = eye;
    d.camera.viewDir = view;
    d.camera.fovDegrees = fov;
    return Scene::build(d);
  }
};

// The pixel-centre rays of a W x H image, as the renderer makes them at one sample per pixel,
// that miss everything.
std::vector<std::pair<int, int>> missedPixels(const Scene& s, int w, int h) {
  std::vector<std::pair<int, int>> missed;
  const Camera& cam = s.camera();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 d = normalize(cam.direction((float(x) + 0.5f) / float(w), (float(y) + 0.5f) / float(h)));
      Hit hit;
      if (!s.intersect(Ray{cam.eye, d, 0, kInf}, hit)) missed.emplace_back(x, y);
    }
  return missed;
}

std::string describe(const std::vector<std::pair<int, int>>& px) {
  std::string s = std::to_string(px.size()) + " pixels, first:";
  for (size_t i = 0; i < px.size() && i < 5; ++i) s += " (" + std::to_string(px[i].first) + "," + std::to_string(px[i].second) + ")";
  return s;
}

const int kResolutions[] = {64, 127, 128, 255, 256, 257};

// A wall filling the view exactly (its diagonals are the image diagonals): every pixel sees it.
TEST(Watertight, HeadOnQuadWallsHaveNoHoles) {
  for (int n : {1, 2, 4, 8})
    for (bool alternate : {false, true}) {
      Builder b;
      b.wall(n, 5, 0, alternate);
      // fov 90 from distance 5: the view's edges are the wall's edges.
      auto s = b.build(Vec3(0, 0, 5), Vec3(0, 0, -1), 90);
      for (int res : kResolutions)
        EXPECT_TRUE(missedPixels(*s, res, res).empty())
            << n << "x" << n << " quads, alternate " << alternate << ", " << res << "px: "
            << describe(missedPixels(*s, res, res));
    }
}

TEST(Watertight, HeadOnTriangleFansHaveNoHoles) {
  for (int k : {4, 8, 16}) {
    Builder b;
    b.fan(k, 5, 0);
    auto s = b.build(Vec3(0, 0, 5), Vec3(0, 0, -1), 80);
    for (int res : kResolutions)
      EXPECT_TRUE(missedPixels(*s, res, res).empty()) << k << " triangles, " << res << "px: " << describe(missedPixels(*s, res, res));
  }
}

// The room: six walls of two triangles each, seen head-on from inside; a closed
// room leaves no ray without a hit.
TEST(Watertight, ClosedRoomOfQuadsSeenHeadOnHasNoHoles) {
  const float h = 2.5f;
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back((i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h);
  // Faces as quads a b c d, split along a-c.
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  std::vector<std::array<int, 3>> t;
  for (const auto& q : quads) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  for (float fov : {39.3f, 60.0f, 90.0f, 120.0f}) {
    Builder b;
    b.mesh(p, t);
    auto s = b.build(Vec3(0, 0, 0), Vec3(0, 0, 1), fov);
    for (int res : kResolutions)
      EXPECT_TRUE(missedPixels(*s, res, res).empty()) << "fov " << fov << ", " << res << "px: " << describe(missedPixels(*s, res, res));
  }
}

// A closed surface around `inside`: rays from there toward `targets` on the surface (its
// shared edges and vertices) never get out. Checks both shadow rays and closest hits.
void expectNoLeak(const Scene& s, Vec3 inside, const std::vector<Vec3>& targets, const char* what) {
  int leaks = 0, misses = 0;
  for (const Vec3& q : targets) {
    Vec3 d = q - inside;
    // Shadow rays as the integrator makes them: to a light well beyond the surface.
    if (!s.occluded(inside, d, 3.0f)) ++leaks;
    Hit hit;
    if (!s.intersect(Ray{inside, normalize(d), 0, kInf}, hit)) ++misses;
  }
  EXPECT_EQ(leaks, 0) << what << ": shadow rays through the surface, of " << targets.size();
  EXPECT_EQ(misses, 0) << what << ": rays without a hit, of " << targets.size();
}

// Points along every edge (cube edges and face diagonals) and at every vertex of a cube of
// 12 triangles, under random rotations and offsets.
std::vector<Vec3> cubeEdgePoints(const Mat4& m) {
  std::vector<Vec3> out;
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.push_back(m.point(Vec3((i & 1) ? 0.5f : -0.5f, (i & 2) ? 0.5f : -0.5f, (i & 4) ? 0.5f : -0.5f)));
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) {
      int diff = __builtin_popcount(unsigned(a ^ b));
      if (diff == 3) continue;  // a space diagonal is no edge
      for (int k = 0; k <= 16; ++k) {
        float f = float(k) / 16;
        out.push_back(v[size_t(a)] * (1 - f) + v[size_t(b)] * f);
      }
    }
  return out;
}

std::vector<std::array<int, 3>> cubeTriangles() {
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  std::vector<std::array<int, 3>> t;
  for (const auto& q : quads) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  return t;
}

TEST(Watertight, ShadowRaysDoNotLeaveAClosedMeshThroughEdgesOrVertices) {
  std::vector<Vec3> unit;
  for (int i = 0; i < 8; ++i) unit.emplace_back((i & 1) ? 0.5f : -0.5f, (i & 2) ? 0.5f : -0.5f, (i & 4) ? 0.5f : -0.5f);
  Rng rng(29, 0);
  for (int trial = 0; trial < 20; ++trial) {
    Mat4 m = trial == 0 ? Mat4::identity()
                        : Mat4::translate(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) *
                              Mat4::rotate(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f, 6.2832f * rng.uniform());
    Builder b;
    b.mesh(unit, cubeTriangles(), m);
    auto s = b.build(Vec3(0, 0, 5), Vec3(0, 0, -1), 60);
    Vec3 centre = m.point(Vec3(0, 0, 0));
    expectNoLeak(*s, centre, cubeEdgePoints(m), "cube mesh from its centre");
    // From points off the centre too: other angles at the same edges.
    for (int k = 0; k < 4; ++k) {
      Vec3 in = m.point(Vec3(0.8f * (rng.uniform() - 0.5f), 0.8f * (rng.uniform() - 0.5f), 0.8f * (rng.uniform() - 0.5f)));
      expectNoLeak(*s, in, cubeEdgePoints(m), "cube mesh from inside");
    }
  }
}

// A light outside a closed mesh, a point on the far side, the segment through an edge: the
// point is in shadow.
TEST(Watertight, ShadowRayThroughACubesEdgeBetweenLightAndPointIsBlocked) {
  std::vector<Vec3> unit;
  for (int i = 0; i < 8; ++i) unit.emplace_back((i & 1) ? 0.5f : -0.5f, (i & 2) ? 0.5f : -0.5f, (i & 4) ? 0.5f : -0.5f);
  Builder b;
  b.mesh(unit, cubeTriangles());
  auto s = b.build(Vec3(0, 0, 5), Vec3(0, 0, -1), 60);
  int leaks = 0, total = 0;
  for (const Vec3& q : cubeEdgePoints(Mat4::identity())) {
    // Through q and on through the cube's centre side: the segment enters at q.
    Vec3 light = q + q * 3.0f;  // outside, on the line from the centre through q
    Vec3 point = q - q * 1.5f;  // past the centre, inside or beyond the far side
    ++total;
    if (!s->occluded(point, light - point, 1.0f)) ++leaks;
    if (!s->occluded(light, point - light, 1.0f)) ++leaks;
  }
  EXPECT_EQ(leaks, 0) << "of " << 2 * total;
}

// The analytic solids: rays from inside toward the rims of capped cylinders and cones and the
// edges and corners of boxes meet the surface there.
TEST(Watertight, ClosedQuadricsHaveNoGapsAtRimsAndEdges) {
  Rng rng(29, 1);
  for (ShapeKind kind : {ShapeKind::Box, ShapeKind::Cylinder, ShapeKind::Cone}) {
    for (int trial = 0; trial < 10; ++trial) {
      Mat4 m = trial == 0 ? Mat4::identity()
                          : Mat4::rotate(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f, 6.2832f * rng.uniform()) *
                                Mat4::scale(0.5f + rng.uniform(), 0.5f + rng.uniform(), 0.5f + rng.uniform());
      Builder b;
      b.shape(kind, m);
      auto s = b.build(Vec3(0, 0, 5), Vec3(0, 0, -1), 60);
      std::vector<Vec3> targets;
      Vec3 inside;
      if (kind == ShapeKind::Box) {
        targets = cubeEdgePoints(m);
        inside = m.point(Vec3(0.1f, -0.05f, 0.02f));
      } else {
        // Both rims: z = 0 (radius 1) and the top (cylinder: z = 1, radius 1; cone: z = 1.5,
        // radius 0.5), at many angles.
        float top = kind == ShapeKind::Cylinder ? 1.0f : 1.5f, rTop = kind == ShapeKind::Cylinder ? 1.0f : 0.5f;
        for (int k = 0; k < 64; ++k) {
          float a = 2 * kPi * float(k) / 64;
          targets.push_back(m.point(Vec3(std::cos(a), std::sin(a), 0)));
          targets.push_back(m.point(Vec3(rTop * std::cos(a), rTop * std::sin(a), top)));
        }
        for (Vec3 e : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)}) {
          targets.push_back(m.point(e));
          targets.push_back(m.point(Vec3(e.x * rTop, e.y * rTop, top)));
        }
        inside = m.point(Vec3(0.1f, 0.05f, 0.4f));
      }
      const char* name = kind == ShapeKind::Box ? "box" : kind == ShapeKind::Cylinder ? "cylinder" : "cone";
      expectNoLeak(*s, inside, targets, name);
      if (trial == 0 && kind != ShapeKind::Box) {
        // Rays through the rims to the last bits of a double, where separate side and cap
        // tests can both miss: from many points inside toward rim points that floats hold,
        // nudged along the rim by less than 1e-8 (outward by less than 1e-16).
        float top = kind == ShapeKind::Cylinder ? 1.0f : 1.5f, rTop = kind == ShapeKind::Cylinder ? 1.0f : 0.5f;
        int leaks = 0;
        for (int k = 0; k < 40000; ++k) {
          Vec3 local(0.4f * (rng.uniform() - 0.5f), 0.4f * (rng.uniform() - 0.5f), 0.2f + 0.8f * rng.uniform());
          float e = 16e-9f * (rng.uniform() - 0.5f);
          for (Vec3 r : {Vec3(1, e, 0), Vec3(e, 1, 0), Vec3(-1, e, 0), Vec3(e, -1, 0)})
            for (Vec3 q : {r, Vec3(r.x * rTop, r.y * rTop, top)}) leaks += !s->occluded(local, q - local, 3.0f);
        }
        EXPECT_EQ(leaks, 0) << name << ": shadow rays through a rim, of 320000";
      }
    }
  }
}

}  // namespace
}  // namespace lc::scene
