// Geometry: analytic quadrics in their canonical frame under an affine transform, and
// triangle meshes stored in world space.
//
// Canonical shapes (local frame):
//   sphere    radius 1 at the origin
//   box       the cube [-0.5, 0.5]^3
//   square    [-0.5, 0.5]^2 in the plane z = 0, normal +z
//   cylinder  radius 1 about z, z in [0, 1]; caps at z = 0 and z = 1 when capped
//   cone      along +z, radius bottomRadius at z = 0 to topRadius at z = height; caps when capped
// Texture coordinates (documented in docs/TEXTURES.md):
//   sphere    u = longitude/(2 pi) about z from +x, v = 0.5 + latitude/pi (0 at z = -1)
//   box       per face, two in-plane coordinates + 0.5, right-handed about the outward normal
//   square    (x + 0.5, y + 0.5)
//   cylinder/cone body u = angle/(2 pi), v = z/height; caps ((x/r + 1)/2, (y/r + 1)/2)
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/math.h"
#include "io/scene_desc.h"

namespace lc::scene {

struct Mesh {
  std::vector<Vec3> positions;  // world space
  std::vector<Vec3> normals;    // world space, unit; empty = flat shading
  std::vector<Vec2> uvs;        // empty = none
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangleMaterials;  // empty = the shape's material
  std::vector<int> vertexMaterials;    // empty = none; else blended barycentrically
};

struct Shape {
  io::ShapeKind kind = io::ShapeKind::Sphere;
  Mat4 toWorld = Mat4::identity();
  Mat4 toLocal = Mat4::identity();
  int material = 0;
  int mesh = -1;  // meshes only
  bool capped = true;
  float height = 1, bottomRadius = 1, topRadius = 0;
  Bounds3 bounds;  // world space
  std::string name;
  bool twoSidedEmission = false;  // object lights on both sides (io::ObjectDesc)
  SourceLoc loc;
};

// Intersection of a local-space ray with a canonical quadric: the smallest t in
// (tmin, tmax), or false. `part` identifies the face/cap hit (for normals and uvs).
bool intersectQuadric(const Shape& s, const Vec3& o, const Vec3& d, float tmin, float tmax,
                      float& t, int& part);
// Local-space normal (not normalised) and uv of a local point on a quadric's `part`.
Vec3 quadricLocalNormal(const Shape& s, const Vec3& p, int part);
Vec2 quadricUv(const Shape& s, const Vec3& p, int part);
// A quadric's bounds in its canonical frame (empty for meshes).
Bounds3 quadricLocalBounds(const Shape& s);
// World bounds of a quadric (its local bounding box, transformed).
Bounds3 quadricBounds(const Shape& s);

// The kinds SolidWithMargin decides.
inline bool canProveMeets(const Shape& s) {
  return s.kind == io::ShapeKind::Box || s.kind == io::ShapeKind::Sphere ||
         (s.kind == io::ShapeKind::Cylinder && s.capped);
}
// Box, sphere or capped cylinder s with a margin (world units), for proofs that need no
// ray (the visibility probes). Exact under any affine transform, in double: a world
// displacement of length m moves local coordinate i by at most m times the norm of row i of
// toLocal, so the margin becomes local depths once, here. For other kinds (canProveMeets)
// both tests answer false.
class SolidWithMargin {
 public:
  SolidWithMargin(const Shape& s, float margin);
  bool decides() const { return decides_; }
  // Whether p lies outside the shape grown by the margin. A segment from a point inside a
  // solid runs through it without crossing its surface, which is what stops a ray.
  bool surelyOutside(const Vec3& p) const;
  // Whether the segment o + t d (world space), t in [tLo, tHi], passes through the shape
  // shrunk by the margin: some point of it has the whole ball of that radius inside.
  bool surelyMeets(const Vec3& o, const Vec3& d, float tLo, float tHi) const;

 private:
  void toLocal(const Vec3& p, double* x) const;
  const Shape& s_;
  double m_;
  double row_[3], radial_, frobenius_;  // toLocal's row norms, of x and y together, of all
  bool decides_;
};

// Whether the shape is a convex solid (sphere, box, capped cylinder or cone, a closed
// mesh with every vertex behind every face's plane) or a flat convex polygon (square, a
// planar mesh whose triangles cover exactly the convex hull of its vertices). Any affine
// transform keeps convexity. Meshes over 4096 triangles are not tested (false).
bool isConvexShape(const Shape& s, const Mesh* mesh);

}  // namespace lc::scene
