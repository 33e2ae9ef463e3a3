#include "scene/occluders.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lc::scene {

using io::ShapeKind;

namespace detail {

constexpr uint32_t kLeafPieces = 4;
// Splits of at least this many pieces build their halves in parallel.
constexpr uint32_t kParallelPieces = 1u << 14;

// Pads an extent for the rounding of the float values it was computed from.
inline void pad(float& lo, float& hi) {
  float p = (std::fabs(lo) + std::fabs(hi) + (hi - lo)) * 1e-6f;
  lo -= p;
  hi += p;
}

// The segments from an apex toward the points of a box, each ending `shortfall` before
// its point, lie in two convex hulls: of the apex and the box, and of the apex and the
// segments' ends (the box moved back toward the apex by up to `shortfall`). A piece apart
// from either is apart from the segments; the second sets apart the surface a light lies
// on, which the first only touches.
struct Hull {
  Vec3 apex, c, h;  // the box's centre and half extent
  Vec3 lo, hi;      // the bounding box of both hulls' intersection
  float margin, shortfall;
  float invDMin, invDMax;  // reciprocal distances from the apex to the box (0 when it is inside)
  // The cone from the apex that holds the box, set up when first needed (most pieces are
  // set apart by the bounding boxes alone): none when the apex is near or in the box.
  mutable int cone = -1;  // -1 not set up, 0 none, 1 set
  mutable Vec3 u, v, w, au, av, aw;
  mutable float cos2Angle = 1;  // the cone's half-angle's cosine, squared

  Hull(const Vec3& a, const Vec3& blo, const Vec3& bhi, float m, float s)
      : apex(a), c((blo + bhi) * 0.5f), h((bhi - blo) * 0.5f), margin(m), shortfall(s) {
    Vec3 near = vmax(vmax(blo - a, a - bhi), Vec3(0.0f));
    const float dMin = length(near);
    invDMin = dMin > 0 ? 1 / dMin : 0;
    invDMax = dMin > 0 ? 1 / length(vmax(vabs(blo - a), vabs(bhi - a))) : 0;
    for (int k = 0; k < 3; ++k) {
      Vec3 n(0.0f);
      n[k] = 1;
      extent(n, lo[k], hi[k]);
    }
  }
  // The range of n . wi over the unit directions wi from the apex to the box.
  void directionRange(const Vec3& n, float& lo, float& hi) const {
    if (!(invDMin > 0)) {
      lo = -1;
      hi = 1;
      return;
    }
    float qc = dot(n, c - apex), qh = dot(vabs(n), h);
    float q0 = qc - qh, q1 = qc + qh;
    lo = std::max(-1.0f, q0 * (q0 < 0 ? invDMin : invDMax));
    hi = std::min(1.0f, q1 * (q1 < 0 ? invDMax : invDMin));
  }
  // The extent along unit axis n of the two hulls' intersection.
  void extent(const Vec3& n, float& elo, float& ehi) const {
    float a = dot(n, apex), bc = dot(n, c), bh = dot(vabs(n), h);
    float blo = bc - bh, bhi = bc + bh;
    if (shortfall > 0) {
      float wlo, whi;
      directionRange(n, wlo, whi);
      // An end is its point less shortfall * wi: along n, within these.
      blo = std::max(blo, bc - bh - shortfall * whi);
      bhi = std::min(bhi, bc + bh - shortfall * wlo);
    }
    elo = std::min(a, blo);
    ehi = std::max(a, bhi);
  }
  bool setUpCone() const {
    Vec3 d = c - apex;
    float dist = length(d), r = length(h) + margin;
    cone = 0;
    if (!(dist > 2 * r)) return false;  // a wide cone would rarely set anything apart
    w = d / dist;
    orthonormalBasis(w, u, v);
    au = vabs(u);
    av = vabs(v);
    aw = vabs(w);
    float s = r / dist;
    cos2Angle = 1 - s * s;
    cone = 1;
    return true;
  }
  // Whether box b is apart from the hulls: outside their bounding box or outside the cone.
  bool boxApart(const Bounds3& b) const { return aabbApart(b) || coneApart(b); }
  bool aabbApart(const Bounds3& b) const {
    return b.hi.x < lo.x - margin || b.lo.x > hi.x + margin || b.hi.y < lo.y - margin || b.lo.y > hi.y + margin ||
           b.hi.z < lo.z - margin || b.lo.z > hi.z + margin;
  }
  bool coneApart(const Bounds3& b) const {
    if (cone == 0 || (cone < 0 && !setUpCone())) return false;
    // The largest cosine between w and a vector from the apex into b (bounds.h's
    // cosBoundBox): below the cone's, b lies outside the cone and so outside the hull.
    Vec3 qc = (b.lo + b.hi) * 0.5f - apex, qh = (b.hi - b.lo) * 0.5f;
    float mz = dot(qc, w) + dot(aw, qh);
    if (mz < 0) return true;
    float ax = std::fabs(dot(qc, u)) - dot(au, qh), ay = std::fabs(dot(qc, v)) - dot(av, qh);
    float x2 = ax > 0 ? ax * ax : 0, y2 = ay > 0 ? ay * ay : 0;
    return mz * mz < cos2Angle * (x2 + y2 + mz * mz);  // mz < cos * length, both sides >= 0
  }
  // The hull's faces through the apex: the planes through it and the box's silhouette
  // edges (seen from the apex, an edge between a face that faces it and one that does
  // not), each with the box on its inner side. With the world axes (the box's far faces)
  // they are all the hull's face normals; a piece beyond one of them is apart, though
  // its box meets the hull's bounding box and the cone around it (a canopy beside the
  // wedge from a point to a long row of lights). Set up when first needed.
  mutable int silhouette = -1;  // -1 not set up, else the number of planes
  mutable Vec3 sn[6];
  mutable float sd[6];
  void setUpSilhouette() const {
    silhouette = 0;
    if (!(invDMin > 0)) return;  // the apex in or at the box: no such planes
    const float ap[3] = {apex.x, apex.y, apex.z};
    const float bl[3] = {c.x - h.x, c.y - h.y, c.z - h.z}, bh[3] = {c.x + h.x, c.y + h.y, c.z + h.z};
    // The rounding of the planes' dot products (their offsets are padded by it).
    const float tol = 1e-5f * (maxComponent(vabs(apex)) + maxComponent(vabs(c)) + maxComponent(h));
    // Per axis, where the apex is: below the box's slab (-1), above it (1) or within (0).
    int side[3];
    for (int a = 0; a < 3; ++a) side[a] = ap[a] < bl[a] ? -1 : ap[a] > bh[a] ? 1 : 0;
    for (int k = 0; k < 3; ++k) {
      const int a = (k + 1) % 3, b = (k + 2) % 3;  // the edge runs along k
      if (side[a] == 0 && side[b] == 0) continue;
      for (int sa = 0; sa < 2; ++sa)
        for (int sb = 0; sb < 2; ++sb) {
          // A silhouette edge: the apex is beyond exactly one of its two faces.
          const bool fa = side[a] == (sa ? 1 : -1), fb = side[b] == (sb ? 1 : -1);
          if (fa == fb) continue;
          // The plane through the apex and the edge (x_a, x_b) along axis k has the normal
          // (edge - apex) x e_k, whose k component is 0 (the edge's length, which a flat box
          // has none of, does not enter).
          const float da = (sa ? bh[a] : bl[a]) - ap[a], db = (sb ? bh[b] : bl[b]) - ap[b];
          const float len = std::sqrt(da * da + db * db);
          if (!(len > 0) || !std::isfinite(len)) continue;
          float nv[3];
          nv[k] = 0;
          nv[a] = db / len;
          nv[b] = -da / len;
          Vec3 n(nv[0], nv[1], nv[2]);
          if (dot(n, c) > dot(n, apex)) n = -n;
          // The plane's offset bounds the apex and the whole box as computed, so that the
          // rounding of its normal cannot put a corner of the box outside it
          // (OccluderIndex.ANearlyFlatBoxGivesNoFalsePlanes).
          const float d = std::max(dot(n, apex), dot(n, c) + dot(vabs(n), h));
          sn[silhouette] = n;
          sd[silhouette] = d + tol;
          ++silhouette;
        }
    }
  }
  // Whether box b lies beyond one of those planes (by more than the margin).
  bool silhouetteApart(const Bounds3& b) const {
    if (silhouette < 0) setUpSilhouette();
    const Vec3 bc = (b.lo + b.hi) * 0.5f, bh = (b.hi - b.lo) * 0.5f;
    for (int i = 0; i < silhouette; ++i)
      if (dot(sn[i], bc) - dot(vabs(sn[i]), bh) > sd[i] + margin) return true;
    return false;
  }
  // Whether a plane through the apex and an edge of triangle v separates it from the box:
  // the hull meets that plane only at the apex, the triangle lies on its other side.
  bool triangleApart(const Vec3* v) const {
    const Vec3 e[3] = {v[0] - apex, v[1] - apex, v[2] - apex};
    const Vec3 ca = c - apex;
    for (int i = 0; i < 3; ++i) {
      const Vec3 m = cross(e[i], e[(i + 1) % 3]);
      const float s = dot(m, e[(i + 2) % 3]);
      const float bc = dot(m, ca), bh = dot(vabs(m), h), tol = margin * length(m);
      if ((s > 0 && bc + bh < -tol) || (s < 0 && bc - bh > tol)) return true;
    }
    return false;
  }
  // Whether unit axis n separates the hulls from the extent [plo, phi] along n.
  bool axisApart(const Vec3& n, float plo, float phi) const {
    float elo, ehi;
    extent(n, elo, ehi);
    return ehi < plo - margin || elo > phi + margin;
  }
};

}  // namespace detail

using detail::Hull;
using detail::kLeafPieces;
using detail::kParallelPieces;
using detail::pad;

OccluderIndex::OccluderIndex(const std::vector<Shape>& shapes, const std::vector<Mesh>& meshes)
    : shapes_(&shapes), meshes_(&meshes), built_(true) {
  quadrics_.resize(shapes.size());
  for (size_t si = 0; si < shapes.size(); ++si) {
    const Shape& s = shapes[si];
    if (s.kind == ShapeKind::Mesh) {
      const size_t n = meshes[size_t(s.mesh)].triangles.size();
      for (size_t t = 0; t < n; ++t) pieces_.push_back({uint32_t(si), uint32_t(t)});
      continue;
    }
    pieces_.push_back({uint32_t(si), 0});
    // The shape lies in its local bounds: along each local axis (a row of toLocal, the
    // normal of the local planes x, y or z = const), within the bounds' corners' extent.
    QuadricAxes& q = quadrics_[si];
    q.box = quadricBounds(s);
    const Bounds3 local = quadricLocalBounds(s);
    for (int k = 0; k < 3; ++k) {
      const auto& row = s.toLocal.m[size_t(k)];
      double len = std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
      if (!(len > 0) || !std::isfinite(len)) continue;
      Vec3 n(float(row[0] / len), float(row[1] / len), float(row[2] / len));
      float lo = kInf, hi = -kInf;
      for (int i = 0; i < 8; ++i) {
        Vec3 corner((i & 1) ? local.hi.x : local.lo.x, (i & 2) ? local.hi.y : local.lo.y,
                    (i & 4) ? local.hi.z : local.lo.z);
        float d = dot(n, s.toWorld.point(corner));
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      pad(lo, hi);
      q.axis[q.axes] = n;
      q.lo[q.axes] = lo;
      q.hi[q.axes] = hi;
      ++q.axes;
    }
    if (q.axes != 3) q.axes = 0;  // a degenerate frame: its bounding box alone
    // Axes along the world's (an unrotated box, cylinder or sphere) bound the shape as its
    // bounding box does, which the hull's is tested against first: their tests would
    // repeat that one (14% of a clear test's instructions in a room of boxes).
    bool aligned = q.axes == 3;
    for (int k = 0; k < q.axes; ++k) aligned = aligned && maxComponent(vabs(q.axis[k])) == 1.0f;
    if (aligned) q.axes = 0;
  }
  if (pieces_.empty()) return;
  // Built over an order of the pieces, their boxes and centres computed once (freed after).
  const size_t n = pieces_.size();
  std::vector<Bounds3> boxes(n);
  std::vector<Vec3> centres(n);
  for (size_t i = 0; i < n; ++i) {
    boxes[i] = pieceBox(pieces_[i]);
    centres[i] = boxes[i].center();
  }
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
  nodes_.resize(subtreeNodes(uint32_t(n)));
  build(0, 1, 0, uint32_t(n), order, boxes, centres);
  std::vector<Piece> sorted(n);
  for (size_t i = 0; i < n; ++i) sorted[i] = pieces_[order[i]];
  pieces_.swap(sorted);
}

Bounds3 OccluderIndex::triangle(const Piece& p, Vec3 v[3]) const {
  const Mesh& m = (*meshes_)[size_t((*shapes_)[p.shape].mesh)];
  const auto& tri = m.triangles[p.prim];
  for (int i = 0; i < 3; ++i) v[i] = m.positions[size_t(tri[i])];
  Bounds3 b(v[0], v[1]);
  b.extend(v[2]);
  return b;
}

Bounds3 OccluderIndex::pieceBox(const Piece& p) const {
  if ((*shapes_)[p.shape].kind != ShapeKind::Mesh) return quadrics_[p.shape].box;
  Vec3 v[3];
  return triangle(p, v);
}

// Fills node `self` for the pieces order[begin, end): a leaf, or a split at the median
// centre along the centres' longest axis into two children stored side by side at `below`
// and below + 1, the left child's descendants after them and then the right child's. The
// slots depend on the piece counts alone (subtreeNodes), so the halves of large splits are
// built in parallel (2M triangles: about 1 s on one thread), into the same layout.
void OccluderIndex::build(uint32_t self, uint32_t below, uint32_t begin, uint32_t end, std::vector<uint32_t>& order,
                          const std::vector<Bounds3>& boxes, const std::vector<Vec3>& centres) {
  Bounds3 box, cbox;
  for (uint32_t i = begin; i < end; ++i) {
    box.extend(boxes[order[i]]);
    cbox.extend(centres[order[i]]);
  }
  nodes_[self].box = box;
  if (end - begin <= kLeafPieces) {
    nodes_[self].first = begin;
    nodes_[self].count = end - begin;
    return;
  }
  Vec3 e = cbox.extent();
  const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end, [&](uint32_t a, uint32_t b) {
    float ca = centres[a][axis], cb = centres[b][axis];
    return ca < cb || (ca == cb && a < b);
  });
  nodes_[self].first = below;
  nodes_[self].count = 0;
  const uint32_t leftBelow = below + 2, rightBelow = leftBelow + subtreeNodes(mid - begin) - 1;
  auto left = [&] { build(below, leftBelow, begin, mid, order, boxes, centres); };
  auto right = [&] { build(below + 1, rightBelow, mid, end, order, boxes, centres); };
  if (end - begin >= kParallelPieces) {
    tbb::parallel_invoke(left, right);
  } else {
    left();
    right();
  }
}

uint32_t OccluderIndex::subtreeNodes(uint32_t count) {
  return count <= kLeafPieces ? 1 : 1 + subtreeNodes(count / 2) + subtreeNodes(count - count / 2);
}

bool OccluderIndex::pieceApart(const Hull& hull, const Piece& p, int skip) const {
  if (int(p.shape) == skip) return true;
  const Shape& s = (*shapes_)[p.shape];
  if (s.kind != ShapeKind::Mesh) {
    const QuadricAxes& q = quadrics_[p.shape];
    if (hull.boxApart(q.box)) return true;
    for (int k = 0; k < q.axes; ++k)
      if (hull.axisApart(q.axis[k], q.lo[k], q.hi[k])) return true;
    return hull.silhouetteApart(q.box);
  }
  Vec3 v[3];
  // The triangle is within its vertices' box exactly (the margin covers the hit test's
  // rounding), so the box needs no padding. The cheap tests first: the box, the plane.
  const Bounds3 b = triangle(p, v);
  if (hull.aabbApart(b)) return true;
  // Its plane: the triangle's extent along its normal (one value, padded for rounding).
  Vec3 n = cross(v[1] - v[0], v[2] - v[0]);
  const float len = length(n);
  if (len > 0 && std::isfinite(len)) {
    n = n / len;
    float d0 = dot(n, v[0]), d1 = dot(n, v[1]), d2 = dot(n, v[2]);
    float lo = std::min({d0, d1, d2}), hi = std::max({d0, d1, d2});
    pad(lo, hi);
    if (hull.axisApart(n, lo, hi)) return true;
  }
  return hull.coneApart(b) || hull.triangleApart(v) || hull.silhouetteApart(b);
}

// A point of a segment of the query that lies in the piece as pieceApart sees it (see the
// header) is on both sides of every plane and cone pieceApart could separate the two by, so
// pieceApart answers no. Each segment, toward one of the box's eight corners, ends at least
// `shortfall` short of it: by the largest of its components rather than its length, which
// ends it no later than the length would.
bool OccluderIndex::onSegments(const Vec3& apex, const Vec3& lo, const Vec3& hi, float margin, float shortfall,
                               const Piece& p, int skip) const {
  if (int(p.shape) == skip) return false;
  const bool flat = (*shapes_)[p.shape].kind == ShapeKind::Mesh;
  Vec3 v[3];
  const Bounds3 b = flat ? triangle(p, v) : quadrics_[p.shape].box;
  // Every segment lies in the box around the apex and the query's box: a piece outside it
  // has no point on them (and pieceApart will say so at once).
  const Vec3 slo = vmin(apex, lo), shi = vmax(apex, hi);
  if (b.hi.x < slo.x || b.lo.x > shi.x || b.hi.y < slo.y || b.lo.y > shi.y || b.hi.z < slo.z || b.lo.z > shi.z)
    return false;
  // Whether x lies in the piece's box, widened by `slack`.
  auto inBox = [&](const Vec3& x, float slack) {
    return x.x >= b.lo.x - slack && x.x <= b.hi.x + slack && x.y >= b.lo.y - slack && x.y <= b.hi.y + slack &&
           x.z >= b.lo.z - slack && x.z <= b.hi.z + slack;
  };
  auto corner = [&](int k) { return Vec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z); };
  if (flat) {
    // A triangle: a segment that crosses it inside (by kInside of its barycentric
    // coordinates, beyond their rounding), at a point within half the margin of the
    // triangle's bounding box as computed (a flat triangle's box has no depth): the box,
    // plane, cone, edge-plane and silhouette tests of pieceApart all have it on both sides.
    constexpr float kInside = 1e-4f;
    const Vec3 e1 = v[1] - v[0], e2 = v[2] - v[0], s0 = apex - v[0], qv = cross(s0, e1);
    for (int k = 0; k < 8; ++k) {
      const Vec3 d = corner(k) - apex;
      const float dm = maxComponent(vabs(d));
      const Vec3 pv = cross(d, e2);
      const float det = dot(e1, pv);
      if (!(std::fabs(det) > 0) || !(dm > 0)) continue;
      const float inv = 1 / det;
      const float u = dot(s0, pv) * inv, w = dot(d, qv) * inv, t = dot(e2, qv) * inv;
      if (u >= kInside && w >= kInside && u + w <= 1 - kInside && t >= kInside &&
          t <= 1 - shortfall / dm - kInside && inBox(apex + d * t, 0.5f * margin))
        return true;
    }
    return false;
  }
  // A quadric as pieceApart sees it: its bounding box and, rotated, its extent along each of
  // its axes. The segments are clipped to those slabs four at a time (SSE lanes), and one
  // that keeps a part is checked at that part's midpoint, as computed, so that no rounding of
  // the clipping makes a witness of a point outside.
  const QuadricAxes& q = quadrics_[p.shape];
  auto inside = [&](const Vec3& x) {
    if (!inBox(x, 0)) return false;
    for (int k = 0; k < q.axes; ++k) {
      const float d = dot(q.axis[k], x);
      if (!(d >= q.lo[k] && d <= q.hi[k])) return false;
    }
    return true;
  };
  auto witness = [&](const Vec3& d, float t0, float t1) { return t0 <= t1 && inside(apex + d * (0.5f * (t0 + t1))); };
#if defined(__SSE2__)
  const __m128 one = _mm_set1_ps(1.0f), sf = _mm_set1_ps(shortfall), sign = _mm_set1_ps(-0.0f);
  alignas(16) float t0s[4], t1s[4];
  for (int half = 0; half < 2; ++half) {
    // Corners 4 half + (0..3): x and y vary by lane, z by half.
    const __m128 cx = _mm_setr_ps(lo.x, hi.x, lo.x, hi.x), cy = _mm_setr_ps(lo.y, lo.y, hi.y, hi.y);
    const __m128 cz = _mm_set1_ps(half ? hi.z : lo.z);
    const __m128 dx = _mm_sub_ps(cx, _mm_set1_ps(apex.x)), dy = _mm_sub_ps(cy, _mm_set1_ps(apex.y)),
                 dz = _mm_sub_ps(cz, _mm_set1_ps(apex.z));
    const __m128 m = _mm_max_ps(_mm_max_ps(_mm_andnot_ps(sign, dx), _mm_andnot_ps(sign, dy)), _mm_andnot_ps(sign, dz));
    __m128 t0 = _mm_setzero_ps(), t1 = _mm_sub_ps(one, _mm_div_ps(sf, m));
    auto slab = [&](__m128 d, float a, float blo, float bhi) {
      const __m128 inv = _mm_div_ps(one, d);
      const __m128 ta = _mm_mul_ps(_mm_set1_ps(blo - a), inv), tb = _mm_mul_ps(_mm_set1_ps(bhi - a), inv);
      // NaN (0 * inf, the apex on a slab's plane with d 0 there) leaves t0 and t1 as they are.
      t0 = _mm_max_ps(_mm_min_ps(ta, tb), t0);
      t1 = _mm_min_ps(_mm_max_ps(ta, tb), t1);
    };
    slab(dx, apex.x, b.lo.x, b.hi.x);
    slab(dy, apex.y, b.lo.y, b.hi.y);
    slab(dz, apex.z, b.lo.z, b.hi.z);
    // A rotated quadric: its own slabs too (along its axes: d's and the apex's components).
    for (int k = 0; k < q.axes; ++k) {
      const Vec3& n = q.axis[k];
      const __m128 dn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, _mm_set1_ps(n.x)), _mm_mul_ps(dy, _mm_set1_ps(n.y))),
                                   _mm_mul_ps(dz, _mm_set1_ps(n.z)));
      slab(dn, dot(n, apex), q.lo[k], q.hi[k]);
    }
    int hits = _mm_movemask_ps(_mm_cmple_ps(t0, t1));
    if (!hits) continue;
    _mm_store_ps(t0s, t0);
    _mm_store_ps(t1s, t1);
    for (int k = 0; k < 4; ++k)
      if ((hits >> k & 1) && witness(corner(4 * half + k) - apex, t0s[k], t1s[k])) return true;
  }
  return false;
#else
  for (int k = 0; k < 8; ++k) {
    const Vec3 d = corner(k) - apex;
    float t0 = 0, t1 = 1 - shortfall / maxComponent(vabs(d));
    auto slab = [&](float dn, float a, float blo, float bhi) {
      const float ta = (blo - a) / dn, tb = (bhi - a) / dn;
      if (!std::isnan(ta) && !std::isnan(tb)) {
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
    };
    for (int a = 0; a < 3; ++a) slab(d[a], apex[a], b.lo[a], b.hi[a]);
    for (int a = 0; a < q.axes; ++a) slab(dot(q.axis[a], d), dot(q.axis[a], apex), q.lo[a], q.hi[a]);
    if (witness(d, t0, t1)) return true;
  }
  return false;
#endif
}

bool OccluderIndex::clear(const Vec3& apex, const Vec3& lo, const Vec3& hi, float margin, float shortfall,
                          int skip, uint32_t* hint) const {
  if (!built_) return false;
  if (nodes_.empty()) return true;
  // The piece that stopped the last query is often in the way of this one too (a pillar
  // between the point and a group of clusters): tried first, a "no" costs one piece. Most
  // queries that reach it end there; a segment toward a corner of the box running through
  // it says so before the hull is set up (85% of such "no"s in a room of boxes, where the
  // hull and the piece's full test cost ~5% of the render).
  const bool hinted = hint && *hint < pieces_.size();
  if (hinted && onSegments(apex, lo, hi, margin, shortfall, pieces_[*hint], skip)) return false;
  const Hull hull(apex, lo, hi, margin, shortfall);
  if (hinted && !pieceApart(hull, pieces_[*hint], skip)) return false;
  uint32_t stack[64];
  int top = 0, visits = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (++visits > kMaxVisits) return false;
    if (hull.boxApart(n.box)) continue;
    if (n.count == 0) {
      if (top + 2 > 64) return false;
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
      continue;
    }
    for (uint32_t i = n.first; i < n.first + n.count; ++i) {
      if (pieceApart(hull, pieces_[i], skip)) continue;
      if (hint) *hint = i;
      return false;
    }
  }
  return true;
}

}  // namespace lc::scene
