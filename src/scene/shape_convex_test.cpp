// isConvexShape: which shapes the visibility probes may treat as convex occluders.
#include <gtest/gtest.h>

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
