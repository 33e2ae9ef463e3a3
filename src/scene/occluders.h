// A conservative answer to "can anything stop a shadow ray from this point to that box?":
// the scene's surfaces as convex pieces (each quadric inside its transformed bounding box,
// each mesh triangle in its plane) under a bounding-volume hierarchy, tested against the
// convex hull of the point and the box. When every piece is provably apart from the hull,
// every segment from the point to a point of the box is clear, so a light cluster inside
// the box is unoccluded as a whole: lightcuts then needs no shadow ray for any of its
// lights (evaluator.cpp, --clear-clusters). A "no" proves nothing; it only means the test
// could not separate some piece (or gave up after kMaxVisits steps).
//
// A piece is apart from the hull when some plane separates them (the separating axis
// theorem, on a few of its axes): the world axes (bounding boxes), the piece's own axes (a
// triangle's normal; a quadric's three local axes, with the extent of its local bounds),
// a triangle's planes through the point and its edges, and the cone from the point that
// holds the box (a piece all of whose bounding box is outside the cone is outside the hull).
//
// Embree's BVH is not open to custom queries (rtcPointQuery takes a sphere, rtcCollide
// user geometry only), so the hierarchy is our own: a median split over the pieces, which
// refer to the scene's shapes and triangles (8 bytes each, 24 with the nodes). Built on
// request (scene::BuildOptions::occluders), where lightcuts will ask.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "scene/shape.h"

namespace lc::scene {

namespace detail {
struct Hull;
}

class OccluderIndex {
 public:
  // Nodes and pieces a query may visit before it gives up (answers "not clear"): bounds the
  // cost in scenes of many triangles near the hull, where the answer is rarely yes.
  static constexpr int kMaxVisits = 48;

  // Not built: every query answers "not clear".
  OccluderIndex() = default;
  // Every surface of the scene: its shapes in world space, meshes by their triangles. The
  // vectors must outlive the index (the scene's own); about 24 bytes per triangle.
  OccluderIndex(const std::vector<Shape>& shapes, const std::vector<Mesh>& meshes);

  // Whether no piece can meet a segment from `apex` toward a point of the box [lo, hi] that
  // ends `shortfall` before that point (a shadow ray stopping short of its light): every
  // such segment is then clear of all surfaces. Pieces closer than `margin` count as
  // meeting them (float rounding). The pieces of shape `skip` are left out: the caller
  // knows the segments are apart from it (a convex shape the apex sits on, with the box in
  // front of its tangent plane). `hint`, when given, holds a piece index kept between
  // queries: the piece that answered "no" last, tried first.
  bool clear(const Vec3& apex, const Vec3& lo, const Vec3& hi, float margin, float shortfall = 0,
             int skip = -1, uint32_t* hint = nullptr) const;

  bool built() const { return built_; }
  size_t pieceCount() const { return pieces_.size(); }

 private:
  struct Piece {
    uint32_t shape, prim;  // prim: the triangle of a mesh
  };
  // A quadric's world bounds and three local axes with its extent along each.
  struct QuadricAxes {
    Bounds3 box;
    int axes = 0;  // 3, or 0 for a degenerate frame
    Vec3 axis[3];
    float lo[3], hi[3];
  };
  struct Node {
    Bounds3 box;
    // Inner: children at `first` and first + 1 (in nodes_); leaf: pieces [first, first + count).
    uint32_t first = 0, count = 0;
  };
  Bounds3 pieceBox(const Piece& p) const;
  // A triangle piece's vertices into v, and their box.
  Bounds3 triangle(const Piece& p, Vec3 v[3]) const;
  bool pieceApart(const detail::Hull& hull, const Piece& p, int skip) const;
  // Whether a segment of the query (from the apex toward a corner of the box, ending
  // `shortfall` before it) runs through piece p as pieceApart sees it: then pieceApart would
  // answer no, and the query is not clear. False says nothing.
  bool onSegments(const Vec3& apex, const Vec3& lo, const Vec3& hi, float margin, float shortfall, const Piece& p,
                  int skip) const;
  void build(uint32_t self, uint32_t below, uint32_t begin, uint32_t end, std::vector<uint32_t>& order,
             const std::vector<Bounds3>& boxes, const std::vector<Vec3>& centres);
  static uint32_t subtreeNodes(uint32_t count);  // nodes over `count` pieces

  const std::vector<Shape>* shapes_ = nullptr;
  const std::vector<Mesh>* meshes_ = nullptr;
  bool built_ = false;
  std::vector<Piece> pieces_;
  std::vector<QuadricAxes> quadrics_;  // per shape (meshes' entries unused)
  std::vector<Node> nodes_;
};

}  // namespace lc::scene
