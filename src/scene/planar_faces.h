// Meshes (and squares) as flat convex faces, for proving light clusters hidden without rays.
//
// Lightcuts' visibility probes (evaluator.cpp, "Hidden clusters") prove a cluster hidden
// when one convex object stops every shadow ray toward its box. Quadrics and whole convex
// meshes are such objects; a room's walls, slabs and piers written as one triangle mesh
// are not. But each flat face of such a mesh (a wall's side, a slab's top: coplanar
// triangles joined along shared edges whose union is a convex polygon) is a convex object
// too: the directions from a point whose rays cross it form a convex cone. So a shadow ray
// stopped by a triangle names the face that triangle belongs to, and the probe asks
// whether every corner's segment crosses that face, well inside its edges.
//
// A region of coplanar triangles joined across shared edges that covers its convex hull
// exactly is one face (convexRegions). Other faces are grown greedily from each triangle
// across edges it shares (by vertex index) with coplanar triangles, while the polygon
// stays convex; a triangle no neighbour joins is a face of its own. The polygon is exactly the union of its triangles: a triangle
// joins across an edge of the polygon's boundary, from outside it, so none overlap.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "scene/shape.h"

namespace lc::scene {

namespace detail {
struct D3 {  // a point or vector in double, for building faces
  double x, y, z;
};
}  // namespace detail

class PlanarFaces {
 public:
  // Scenes whose meshes hold more triangles than this in all get no mesh faces (4 bytes
  // per triangle and about 100 per face, up to ~55 MB here): their probes use rays as before.
  static constexpr size_t kMaxTriangles = size_t(1) << 19;
  // A face stops growing at this many corners (a fan of many thin triangles).
  static constexpr int kMaxCorners = 24;

  PlanarFaces() = default;
  // The faces of every mesh shape (transmissive ones too: the caller checks materials).
  PlanarFaces(const std::vector<Shape>& shapes, const std::vector<Mesh>& meshes);

  // The face that triangle `prim` of shape `shape` belongs to, or -1.
  int faceOf(int shape, int prim) const {
    if (size_t(shape) >= firstTriangle_.size() || firstTriangle_[size_t(shape)] < 0) return -1;
    return triFace_[size_t(firstTriangle_[size_t(shape)]) + size_t(prim)];
  }
  size_t size() const { return faces_.size(); }
  // The face's bounds (of its corners).
  const Bounds3& bounds(int face) const { return faces_[size_t(face)].box; }
  // How far its triangles' corners lie off its plane (rounding of the mesh's coordinates).
  float thickness(int face) const { return faces_[size_t(face)].thickness; }
  int corners(int face) const { return int(faces_[size_t(face)].edgeCount); }

  // Whether every segment from p along dirs[0, n) (unit) crosses the face more than
  // `margin` inside its edges, between `margin` past p and `margin` before tMax, where
  // segments that run within `margin` of these do the same: 1 yes, -1 cannot tell (p lies
  // within the margin of the plane and every segment crosses it within the margin of the
  // face: the rays may well meet it), else 0 (not proven; so too when p lies within the
  // margin of the plane beside the face). A crossing's inset grows as
  // 1/cos of the angle to the normal: a segment moved sideways by d meets a plane
  // crossed at that angle up to d / cos further along it.
  int crossesAll(int face, const Vec3& p, const Vec3* dirs, int n, float tMax, float margin) const;
  // For a convex mesh shape (Scene::isConvex): whether every segment from p along dirs[0, n)
  // passes through the solid shrunk by `margin`, between `margin` past p and `margin` before
  // tMax: 1 yes, 0 not proven, -1 cannot tell (the mesh bounds no solid and is not one
  // face, or p is not surely outside it). A mesh open along one plane (a box without its
  // bottom) counts as closed by that plane, and a segment must leave it before tMax. A flat
  // convex mesh of one face is asked crossesAll, and what that does not prove is left to
  // the rays (-1).
  int solidMeetsAll(int shape, const Vec3& p, const Vec3* dirs, int n, float tMax, float margin) const;
  // The face of a square shape (every square is one), or -1.
  int squareFace(int shape) const { return size_t(shape) < squareFace_.size() ? squareFace_[size_t(shape)] : -1; }

 private:
  struct Face {
    Vec3 normal;  // unit
    float offset;  // dot(normal, x) = offset on the plane
    Bounds3 box;
    float thickness;
    uint32_t edgeBegin, edgeCount;
  };
  // An edge's inward half-plane within the face's plane: dot(inward, x) >= at inside.
  struct Edge {
    Vec3 inward;
    float at;
  };
  // A mesh shape's faces (a run of faces_), with their normals turned outward, and whether
  // the mesh bounds a solid, closed or open along one plane (solidOf).
  struct Solid {
    uint32_t faceBegin = 0, faceEnd = 0;
    bool solid = false, open = false;
    Face opening{};  // open: the boundary's plane (no edges), normal outward
  };
  static Solid solidOf(const Mesh& m);
  // Whether every segment from p, which lies within mg of the face's plane (signed distance
  // sp), crosses that plane within mg of the face (inside its edges moved out by mg): where
  // the rays may meet it.
  bool nearCrossingsInside(const Face& f, const Vec3& p, float sp, const Vec3* dirs, int n, float mg) const;
  void addFace(const std::vector<detail::D3>& corners, const detail::D3& n, double off, double thick);
  void convexRegions(const Mesh& m, const std::vector<std::pair<uint64_t, uint32_t>>& edgeTris, size_t base);
  std::vector<Solid> solids_;  // per shape
  std::vector<int> squareFace_;  // per shape: a square's face, else -1
  std::vector<int64_t> firstTriangle_;  // per shape: offset of its triangles in triFace_, or -1
  std::vector<int32_t> triFace_;
  std::vector<Face> faces_;
  std::vector<Edge> edges_;
};

}  // namespace lc::scene
