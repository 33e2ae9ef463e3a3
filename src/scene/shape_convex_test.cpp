// isConvexShape: which shapes the visibility probes may treat as convex occluders; and
// SolidWithMargin, which lets a probe prove a box or sphere in the way without rays.
#include <gtest/gtest.h>

#include <random>

#include "scene/shape.h"

namespace lc::scene {
namespace {

using io::ShapeKind;

Shape meshShape() {
  Shape s;
  s.kind = ShapeKind::Mesh;
  return s;
}

// The unit cube's faces as quads (two triangles each), each face with its own four
// vertices (as meshes from files often have), optionally without some faces.
Mesh cube(std::vector<int> skipFaces = {}) {
  const Vec3 c[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  Mesh m;
  for (int f = 0; f < 6; ++f) {
    if (std::find(skipFaces.begin(), skipFaces.end(), f) != skipFaces.end()) continue;
    int b = int(m.positions.size());
    for (int k = 0; k < 4; ++k) m.positions.push_back(c[faces[f][k]]);
    m.triangles.push_back({b, b + 1, b + 2});
    m.triangles.push_back({b, b + 2, b + 3});
  }
  return m;
}

TEST(ConvexShape, QuadricsAreConvexButOpenTubes) {
  for (ShapeKind k : {ShapeKind::Sphere, ShapeKind::Box, ShapeKind::Square, ShapeKind::Cylinder, ShapeKind::Cone}) {
    Shape s;
    s.kind = k;
    EXPECT_TRUE(isConvexShape(s, nullptr)) << int(k);
    s.capped = false;
    bool tube = k == ShapeKind::Cylinder || k == ShapeKind::Cone;
    EXPECT_EQ(isConvexShape(s, nullptr), !tube) << int(k);
  }
}

TEST(ConvexShape, ClosedCubeAndCubeOpenOnOneFace) {
  Shape s = meshShape();
  Mesh closed = cube();
  EXPECT_TRUE(isConvexShape(s, &closed));
  Mesh open = cube({0});  // a box standing on the floor, without its bottom
  EXPECT_TRUE(isConvexShape(s, &open));
  Mesh tube = cube({0, 1});  // open at both ends: a line can pass through
  EXPECT_FALSE(isConvexShape(s, &tube));
}

TEST(ConvexShape, DentedSolidIsNot) {
  Shape s = meshShape();
  Mesh m = cube();
  // Push the top face's centre in: split the top quad into four triangles around a dent.
  Mesh dented;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    bool top = m.positions[size_t(m.triangles[t][0])].z == 1 && m.positions[size_t(m.triangles[t][1])].z == 1 &&
               m.positions[size_t(m.triangles[t][2])].z == 1;
    if (!top) {
      int b = int(dented.positions.size());
      for (int k : m.triangles[t]) dented.positions.push_back(m.positions[size_t(k)]);
      dented.triangles.push_back({b, b + 1, b + 2});
    }
  }
  int b = int(dented.positions.size());
  for (Vec3 p : {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1), Vec3(0.5f, 0.5f, 0.7f)})
    dented.positions.push_back(p);
  for (int k = 0; k < 4; ++k) dented.triangles.push_back({b + k, b + (k + 1) % 4, b + 4});
  EXPECT_FALSE(isConvexShape(s, &dented));
}

TEST(ConvexShape, FlatMeshesAreConvexWhenTheyFillTheirHull) {
  Shape s = meshShape();
  Mesh quad;
  quad.positions = {{0, 0, 0}, {2, 0, 0}, {2, 0, 1}, {0, 0, 1}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_TRUE(isConvexShape(s, &quad));
  Mesh ell;  // an L of three unit squares: not its hull
  ell.positions = {{0, 0, 0}, {2, 0, 0}, {2, 0, 1}, {1, 0, 1}, {1, 0, 2}, {0, 0, 2}, {1, 0, 0}, {0, 0, 1}};
  ell.triangles = {{0, 6, 3}, {0, 3, 7}, {6, 1, 2}, {6, 2, 3}, {7, 3, 4}, {7, 4, 5}};
  EXPECT_FALSE(isConvexShape(s, &ell));
}

}  // namespace
}  // namespace lc::scene

namespace lc::scene {
namespace {

// A box or sphere turned, stretched and moved: toWorld = T R S, toLocal its inverse.
Shape placed(io::ShapeKind kind) {
  Shape s;
  s.kind = kind;
  const Vec3 axis = normalize(Vec3(1, 2, 0.5f));
  s.toWorld = Mat4::translate(1, 2, 3) * Mat4::rotate(axis.x, axis.y, axis.z, 0.7) * Mat4::scale(2, 0.3, 1);
  s.toLocal = Mat4::scale(0.5, 1 / 0.3, 1) * Mat4::rotate(axis.x, axis.y, axis.z, -0.7) * Mat4::translate(-1, -2, -3);
  return s;
}

// Whether the world segment o + t d, t in [t0, t1], meets the shape (its own hit test).
bool hits(const Shape& s, const Vec3& o, const Vec3& d, float t0, float t1) {
  float t;
  int part;
  const Vec3 lo = s.toLocal.point(o), ld = s.toLocal.vector(d);
  // Inside at t0 counts too (the hit test finds only the surface ahead).
  const Vec3 start = lo + ld * t0;
  const bool inside =
      s.kind == io::ShapeKind::Box        ? std::fabs(start.x) < 0.5f && std::fabs(start.y) < 0.5f && std::fabs(start.z) < 0.5f
      : s.kind == io::ShapeKind::Cylinder ? start.x * start.x + start.y * start.y < 1 && start.z > 0 && start.z < 1
                                          : length2(start) < 1;
  return inside || intersectQuadric(s, lo, ld, t0, t1, t, part);
}

// SolidWithMargin claims a segment only when every segment within `margin` of it meets
// the shape too (the shadow rays a probe stands for leave from near the point), and never
// when it misses or only grazes the shape.
TEST(ShapeMeets, SegmentsClaimedPassDeepThroughBoxesSpheresAndCylinders) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  const float margin = 0.04f;
  for (io::ShapeKind kind : {io::ShapeKind::Box, io::ShapeKind::Sphere, io::ShapeKind::Cylinder}) {
    const Shape s = placed(kind);
    int claimed = 0, missed = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 o = Vec3(1, 2, 3) + Vec3(u(rng), u(rng), u(rng)) * 6.0f;
      const Vec3 aim = Vec3(1, 2, 3) + Vec3(u(rng), u(rng), u(rng)) * 1.5f;
      const float len = length(aim - o);
      const Vec3 d = (aim - o) / len;
      const float t1 = len * 1.5f;
      if (!SolidWithMargin(s, margin).surelyMeets(o, d, 0, t1)) {
        missed += !hits(s, o, d, 0, t1);
        continue;
      }
      ++claimed;
      ASSERT_TRUE(hits(s, o, d, 0, t1)) << i;
      for (int k = 0; k < 12; ++k) {
        // Another segment whose ends lie within the margin of this one's, and nearly the same length.
        const Vec3 shiftO = normalize(Vec3(u(rng), u(rng), u(rng))) * (0.9f * margin * std::fabs(u(rng)));
        const Vec3 shiftE = normalize(Vec3(u(rng), u(rng), u(rng))) * (0.9f * margin * std::fabs(u(rng)));
        const Vec3 o2 = o + shiftO, e2 = o + d * t1 + shiftE;
        const float len2 = length(e2 - o2);
        ASSERT_TRUE(hits(s, o2, (e2 - o2) / len2, 0, len2)) << i << " " << k;
      }
    }
    EXPECT_GT(claimed, 200) << int(kind);
    EXPECT_GT(missed, 200) << int(kind);
  }
  // A point inside a shape, or on its surface, is not surely outside it; one beyond the
  // margin is.
  for (io::ShapeKind kind : {io::ShapeKind::Box, io::ShapeKind::Sphere, io::ShapeKind::Cylinder}) {
    const Shape s = placed(kind);
    const Vec3 centre = s.toWorld.point(kind == io::ShapeKind::Cylinder ? Vec3(0, 0, 0.5f) : Vec3(0));
    const Vec3 surface = s.toWorld.point(kind == io::ShapeKind::Cylinder ? Vec3(1, 0, 0.5f) : Vec3(0.5f, 0, 0));
    EXPECT_FALSE(SolidWithMargin(s, margin).surelyOutside(centre)) << int(kind);
    EXPECT_FALSE(SolidWithMargin(s, margin).surelyOutside(surface)) << int(kind);
    EXPECT_TRUE(SolidWithMargin(s, margin).surelyOutside(centre + Vec3(20, 0, 0))) << int(kind);
  }
  // The unit box, as given: a segment through its middle is claimed, one that passes
  // within the margin of a face is not, nor one that ends before the box or starts after it.
  Shape box;
  box.kind = io::ShapeKind::Box;
  EXPECT_TRUE(SolidWithMargin(box, 0.01f).surelyMeets(Vec3(-2, 0, 0), Vec3(1, 0, 0), 0, 4));
  EXPECT_FALSE(SolidWithMargin(box, 0.01f).surelyMeets(Vec3(-2, 0.495f, 0), Vec3(1, 0, 0), 0, 4));
  EXPECT_FALSE(SolidWithMargin(box, 0.2f).surelyMeets(Vec3(-2, 0, 0), Vec3(1, 0, 0), 0, 1.4f));
  EXPECT_FALSE(SolidWithMargin(box, 0.2f).surelyMeets(Vec3(-2, 0, 0), Vec3(1, 0, 0), 2.6f, 4));
  // Shapes it does not decide: flat ones, open tubes, cones, meshes.
  for (io::ShapeKind kind : {io::ShapeKind::Square, io::ShapeKind::Cylinder, io::ShapeKind::Cone, io::ShapeKind::Mesh}) {
    Shape other;
    other.kind = kind;
    other.capped = kind != io::ShapeKind::Cylinder;
    EXPECT_FALSE(canProveMeets(other));
    EXPECT_FALSE(SolidWithMargin(other, 0.01f).surelyMeets(Vec3(-2, 0, 0.5f), Vec3(1, 0, 0), 0, 4));
  }
}

}  // namespace
}  // namespace lc::scene
