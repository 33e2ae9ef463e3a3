// PlanarFaces: meshes split into flat convex faces, and segments proven to cross them.
#include "scene/planar_faces.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

#include "core/rng.h"

namespace lc::scene {
namespace {

// Adds an axis-aligned box to m (eight shared corners, twelve outward triangles).
void addBox(Mesh& m, const Vec3& lo, const Vec3& hi) {
  const int b = int(m.positions.size());
  for (int k = 0; k < 8; ++k)
    m.positions.push_back(Vec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({b + q[0], b + q[1], b + q[2]});
    m.triangles.push_back({b + q[0], b + q[2], b + q[3]});
  }
}

// A mesh of one shape, its points turned by `turn` (a rotation about a slanted axis).
struct OneMesh {
  std::vector<Shape> shapes;
  std::vector<Mesh> meshes;
  explicit OneMesh(Mesh m) {
    Shape s;
    s.kind = io::ShapeKind::Mesh;
    s.mesh = 0;
    shapes.push_back(s);
    meshes.push_back(std::move(m));
  }
};

Vec3 turn(const Vec3& v, float angle) {
  const Vec3 k = normalize(Vec3(1, 2, 0.5f));
  const float c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

TEST(PlanarFaces, ABoxMeshIsSixQuadrilaterals) {
  Mesh m;
  addBox(m, Vec3(-1, 0, -2), Vec3(1, 0.5f, 2));
  OneMesh one(m);
  PlanarFaces f(one.shapes, one.meshes);
  ASSERT_EQ(f.size(), 6u);
  for (int q = 0; q < 6; ++q) {
    EXPECT_EQ(f.faceOf(0, 2 * q), f.faceOf(0, 2 * q + 1)) << q;
    EXPECT_EQ(f.corners(f.faceOf(0, 2 * q)), 4) << q;
  }
  EXPECT_EQ(f.faceOf(1, 0), -1);  // no such shape
}

// From p, no face may claim the segment toward `gap` (through a hole in the mesh), and
// exactly one must claim the one toward `cover` (through the mesh).
void expectGapAndCover(const PlanarFaces& f, const Vec3& p, const Vec3& gap, const Vec3& cover) {
  Vec3 through[1] = {normalize(gap - p)}, onto[1] = {normalize(cover - p)};
  int claims = 0;
  for (int face = 0; face < int(f.size()); ++face) {
    EXPECT_EQ(f.crossesAll(face, p, through, 1, 10, 1e-4f), 0) << face;
    claims += f.crossesAll(face, p, onto, 1, 10, 1e-4f) == 1;
  }
  EXPECT_EQ(claims, 1);
}

// An n x n grid of unit squares in the plane y = 0, two triangles each, without the square
// at (hole, hole) when hole >= 0.
Mesh grid(int n, int hole = -1) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) m.positions.push_back(Vec3(float(i), 0, float(j)));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == hole && j == hole) continue;
      const int a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  return m;
}

// A grid of 20 x 20 squares, as a floor is often written, is one rectangle: corners on its
// straight edges do not count against the face's corner limit.
TEST(PlanarFaces, AGridIsOneRectangle) {
  const int n = 20;
  OneMesh one(grid(n));
  PlanarFaces f(one.shapes, one.meshes);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f.corners(0), 4);
  for (int t = 0; t < 2 * n * n; ++t) EXPECT_EQ(f.faceOf(0, t), 0) << t;
}

// The same grid with its middle square left out: its hole is never claimed, and the ring
// around it is still covered.
TEST(PlanarFaces, AGridWithAHoleNeverClaimsTheHole) {
  OneMesh one(grid(5, 2));
  PlanarFaces f(one.shapes, one.meshes);
  ASSERT_GT(f.size(), 1u);
  expectGapAndCover(f, Vec3(2.5f, -2, 2.5f), Vec3(2.5f, 1, 2.5f), Vec3(0.5f, 1, 4.5f));
}

// An L of three unit squares in one plane: not convex, so no face may hold all of it, and
// no segment through the missing square may be claimed.
TEST(PlanarFaces, AnLShapeSplitsAndItsNotchIsNeverClaimed) {
  Mesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0),
                 Vec3(2, 1, 0), Vec3(0, 2, 0), Vec3(1, 2, 0)};
  m.triangles = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {3, 4, 7}, {3, 7, 6}};
  OneMesh one(m);
  PlanarFaces f(one.shapes, one.meshes);
  ASSERT_GE(f.size(), 2u);
  std::set<int> faces;
  for (int t = 0; t < 6; ++t) faces.insert(f.faceOf(0, t));
  EXPECT_EQ(faces.size(), f.size());
  EXPECT_EQ(faces.count(-1), 0u);
  // From below the plane, toward points above it: through the notch (1..2, 1..2), never;
  // through the middle of the first square, some face must claim it.
  expectGapAndCover(f, Vec3(0.5f, 0.5f, -1), Vec3(1.5f, 1.5f, 0), Vec3(0.5f, 0.5f, 1));
}

// Whether the segment o + d t, t in [0, tMax], meets triangle (a, b, c), in double.
bool meets(const Vec3& o, const Vec3& d, float tMax, const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<double, 3> e1{b.x - a.x, b.y - a.y, b.z - a.z}, e2{c.x - a.x, c.y - a.y, c.z - a.z},
      dd{d.x, d.y, d.z}, s{o.x - a.x, o.y - a.y, o.z - a.z};
  auto cr = [](const std::array<double, 3>& u, const std::array<double, 3>& v) {
    return std::array<double, 3>{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  };
  auto dt = [](const std::array<double, 3>& u, const std::array<double, 3>& v) {
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  };
  const auto pv = cr(dd, e2);
  const double det = dt(e1, pv);
  if (det == 0) return false;
  const double u = dt(s, pv) / det;
  const auto qv = cr(s, e1);
  const double v = dt(dd, qv) / det, t = dt(e2, qv) / det;
  return u >= 0 && v >= 0 && u + v <= 1 && t >= 0 && t <= tMax;
}

// A random unit direction in the hull of dirs[0, 4).
Vec3 inHull(const Vec3* dirs, Rng& rng) {
  float w[4], sum = 0;
  for (float& x : w) sum += x = rng.uniform();
  Vec3 d(0.0f);
  for (int k = 0; k < 4; ++k) d += dirs[k] * (w[k] / sum);
  return normalize(d);
}

// p moved by `margin` in a random direction.
Vec3 nudged(const Vec3& p, float margin, Rng& rng) {
  return p + normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f)) * margin;
}

// Whatever a face claims, the segments near the claimed ones meet its triangles: from
// random points toward random small fans of directions, every direction in the fan's hull,
// from an origin moved by up to the margin, meets a triangle of the face before tMax. The
// mesh holds two turned boxes side by side and a fan of eleven triangles.
TEST(PlanarFaces, SegmentsNearClaimedOnesMeetTheFacesTriangles) {
  Mesh m;
  addBox(m, Vec3(-1, 0, -2), Vec3(1, 0.5f, 2));
  addBox(m, Vec3(1, 0, -2), Vec3(3, 0.5f, 0));
  const int fanCentre = int(m.positions.size());
  m.positions.push_back(Vec3(0, 3, 0));
  for (int k = 0; k < 12; ++k)
    m.positions.push_back(Vec3(1.5f * std::cos(0.4f * float(k)), 3, 1.5f * std::sin(0.4f * float(k))));
  for (int k = 0; k + 1 < 12; ++k) m.triangles.push_back({fanCentre, fanCentre + 1 + k, fanCentre + 2 + k});
  for (Vec3& v : m.positions) v = turn(v, 0.7f) + Vec3(0.3f, -0.2f, 0.1f);
  OneMesh one(m);
  PlanarFaces f(one.shapes, one.meshes);
  EXPECT_LT(f.size(), m.triangles.size() / 2 + 2);  // the quads and most of the fan merged
  Rng rng(41, 3);
  const float margin = 2e-3f;
  int claims = 0, checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 p = Vec3(rng.uniform() * 10 - 5, rng.uniform() * 10 - 5, rng.uniform() * 10 - 5);
    // Aimed near a corner or along an edge, in fans from wide to a few margins across.
    const auto& tr = m.triangles[size_t(rng.uniform() * float(m.triangles.size() - 1))];
    const float along = rng.uniform();
    const Vec3 aim = m.positions[size_t(tr[0])] * along + m.positions[size_t(tr[1])] * (1 - along);
    const float spread = 0.6f * std::pow(rng.uniform(), 4.0f) + 4 * margin;
    Vec3 dirs[4];
    for (Vec3& d : dirs)
      d = normalize(aim + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * spread - p);
    const float tMax = length(aim - p) + 2 * rng.uniform();
    for (int face = 0; face < int(f.size()); ++face) {
      if (f.crossesAll(face, p, dirs, 4, tMax, margin) != 1) continue;
      ++claims;
      for (int s = 0; s < 20; ++s) {
        const Vec3 d = inHull(dirs, rng), o = nudged(p, margin, rng);
        bool hit = false;
        for (size_t t = 0; t < m.triangles.size() && !hit; ++t) {
          if (f.faceOf(0, int(t)) != face) continue;
          const auto& tr = m.triangles[t];
          hit = meets(o, d, tMax - margin, m.positions[size_t(tr[0])], m.positions[size_t(tr[1])],
                      m.positions[size_t(tr[2])]);
        }
        ++checked;
        EXPECT_TRUE(hit) << "trial " << trial << " face " << face;
      }
    }
  }
  EXPECT_GT(claims, 100);
  EXPECT_GT(checked, 2000);
}

// A box as five quads of their own corners, open at the bottom (the Cornell box's blocks),
// and the same box closed with shared corners, both turned: whatever solidMeetsAll claims,
// every direction in the fan's hull, from an origin moved by the margin, meets a triangle
// before tMax, lights inside the box and points below its opening included.
TEST(PlanarFaces, SolidsClaimOnlySegmentsTheirTrianglesStop) {
  Mesh open;
  const Vec3 lo(-1, 0, -0.5f), hi(1, 1.5f, 0.5f);
  const int quads[5][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    const int b = int(open.positions.size());
    for (int k : q) open.positions.push_back(Vec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z));
    open.triangles.push_back({b, b + 1, b + 2});
    open.triangles.push_back({b, b + 2, b + 3});
  }
  Mesh closed;
  addBox(closed, lo, hi);
  for (Mesh* m : {&open, &closed})
    for (Vec3& v : m->positions) v = turn(v, 0.4f) + Vec3(0.2f, 0.1f, -0.3f);
  const Vec3 centre = turn((lo + hi) * 0.5f, 0.4f) + Vec3(0.2f, 0.1f, -0.3f);
  for (const Mesh* m : {&open, &closed}) {
    OneMesh one(*m);
    PlanarFaces f(one.shapes, one.meshes);
    Rng rng(43, 5);
    const float margin = 2e-3f;
    int claims = 0, inside = 0, undecided = 0;
    for (int trial = 0; trial < 20000; ++trial) {
      const Vec3 p = centre + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * 8.0f;
      const Vec3 aim = centre + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * 3.0f;
      const float spread = 0.8f * std::pow(rng.uniform(), 3.0f) + 4 * margin;
      Vec3 dirs[4];
      for (Vec3& d : dirs)
        d = normalize(aim + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * spread - p);
      // Half the fans end near their aim (often inside the box), half well past it.
      const float tMax = length(aim - p) * (trial % 2 ? 1.0f : 2.5f);
      const int r = f.solidMeetsAll(0, p, dirs, 4, tMax, margin);
      undecided += r == -1;  // only from inside the box (0.6% of the trials' volume)
      if (r != 1) continue;
      ++claims;
      inside += trial % 2;
      for (int s = 0; s < 20; ++s) {
        const Vec3 d = inHull(dirs, rng), o = nudged(p, margin, rng);
        bool hit = false;
        for (const auto& tr : m->triangles)
          hit = hit || meets(o, d, tMax - margin, m->positions[size_t(tr[0])], m->positions[size_t(tr[1])],
                             m->positions[size_t(tr[2])]);
        EXPECT_TRUE(hit) << "trial " << trial << (m == &open ? " open" : " closed");
      }
    }
    EXPECT_GT(claims, 200);
    EXPECT_GT(inside, 20);
    EXPECT_LT(undecided, 400);
  }
}

// The faces of a box from (-1, 0, -1) to (1, 1, 1), and its top quad's (y = 1).
struct BoxTop {
  OneMesh one;
  PlanarFaces faces;
  int top;
  BoxTop() : one(mesh()), faces(one.shapes, one.meshes), top(faces.faceOf(0, 2 * 3)) {}
  static Mesh mesh() {
    Mesh m;
    addBox(m, Vec3(-1, 0, -1), Vec3(1, 1, 1));
    return m;
  }
};

// A point in the face's plane, a grazing fan, one that turns away and a face beyond tMax
// are not proven.
TEST(PlanarFaces, PointsInThePlaneGrazingFansAndFarFacesAreNotProven) {
  BoxTop box;
  const PlanarFaces& f = box.faces;
  const int top = box.top;
  ASSERT_GE(top, 0);
  Vec3 down[1] = {Vec3(0, -1, 0)};
  EXPECT_EQ(f.crossesAll(top, Vec3(0.2f, 3, 0.1f), down, 1, 10, 1e-3f), 1);
  EXPECT_EQ(f.crossesAll(top, Vec3(0.2f, 3, 0.1f), down, 1, 1.5f, 1e-3f), 0);  // stops short
  EXPECT_EQ(f.crossesAll(top, Vec3(5, 1, 0), down, 1, 10, 1e-3f), 0);          // in the plane
  Vec3 graze[1] = {normalize(Vec3(-1, -0.01f, 0))};
  EXPECT_EQ(f.crossesAll(top, Vec3(2.5f, 1.02f, 0), graze, 1, 10, 1e-3f), 0);
  Vec3 away[1] = {Vec3(0, 1, 0)};
  EXPECT_EQ(f.crossesAll(top, Vec3(0.2f, 3, 0.1f), away, 1, 10, 1e-3f), 0);
  // Near an edge, within the margin's inset: not proven.
  Vec3 edge[1] = {normalize(Vec3(0.9995f, 1, 0) - Vec3(0.9995f, 3, 0))};
  EXPECT_EQ(f.crossesAll(top, Vec3(0.9995f, 3, 0), edge, 1, 10, 1e-3f), 0);
}

// Where the face may well stop the rays but the margin keeps the test from proving it, the
// rays are asked (-1): a point within the margin of the plane whose segments cross it on the
// face (a wall just behind a window mesh). Beside the face: 0.
TEST(PlanarFaces, PointsJustBehindAFaceAreLeftToTheRays) {
  BoxTop box;
  const PlanarFaces& f = box.faces;
  const int top = box.top;
  ASSERT_GE(top, 0);
  const float margin = 1e-3f;
  Vec3 down[2] = {normalize(Vec3(0.3f, -1, 0)), normalize(Vec3(-0.2f, -1, 0.1f))};
  EXPECT_EQ(f.crossesAll(top, Vec3(0, 1.0005f, 0), down, 2, 10, margin), -1);     // through the face
  EXPECT_EQ(f.crossesAll(top, Vec3(0, 0.9995f, 0), down, 2, 10, margin), 0);      // leaving the plane
  EXPECT_EQ(f.crossesAll(top, Vec3(1.01f, 1.0005f, 0), down, 2, 10, margin), 0);  // beside the face
  Vec3 slant[2] = {normalize(Vec3(10, -1, 0)), down[1]};
  EXPECT_EQ(f.crossesAll(top, Vec3(0.999f, 1.0005f, 0), slant, 2, 10, margin), 0);  // one crosses beside it
}

// A flat convex mesh (a panel of two triangles) answers its probes as its one face where
// that proves them, and leaves the rest to the rays (-1), never "not proven": before whole
// regions, such a mesh of several faces sent every probe to the rays, which prove more
// (no inset at the edges).
TEST(PlanarFaces, AFlatConvexMeshLeavesWhatItsFaceCannotProveToTheRays) {
  Mesh m;
  m.positions = {Vec3(-1, 1, -1), Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(-1, 1, 1)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  OneMesh one(m);
  PlanarFaces f(one.shapes, one.meshes);
  Vec3 down[2] = {normalize(Vec3(0.1f, -1, 0)), normalize(Vec3(-0.1f, -1, 0.1f))};
  EXPECT_EQ(f.solidMeetsAll(0, Vec3(0, 3, 0), down, 2, 10, 1e-3f), 1);  // well inside
  const int face = f.faceOf(0, 0);
  ASSERT_GE(face, 0);
  Vec3 edge[1] = {normalize(Vec3(0.9995f, 1, 0) - Vec3(0.9995f, 3, 0))};  // within the inset
  EXPECT_EQ(f.crossesAll(face, Vec3(0.9995f, 3, 0), edge, 1, 10, 1e-3f), 0);
  EXPECT_EQ(f.solidMeetsAll(0, Vec3(0.9995f, 3, 0), edge, 1, 10, 1e-3f), -1);
  EXPECT_EQ(f.solidMeetsAll(0, Vec3(5, 3, 0), down, 2, 10, 1e-3f), -1);  // beside it: the rays say no
}

}  // namespace
}  // namespace lc::scene
