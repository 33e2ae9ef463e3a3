#include "scene/planar_faces.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace lc::scene {

using detail::D3;

namespace {

D3 d3(const Vec3& v) { return {v.x, v.y, v.z}; }
D3 sub(const D3& a, const D3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 crossd(const D3& a, const D3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dotd(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double lend(const D3& a) { return std::sqrt(dotd(a, a)); }

// Relative tolerances: a neighbour is coplanar when its normal is within ~0.1 mrad and its
// corners within kPlaneTol of the face's extent off its plane; a corner is convex unless its
// turn is more than kTurnTol (relative) the other way.
constexpr double kNormalTol = 1e-8;  // 1 - |cos| of the angle between the normals
constexpr double kPlaneTol = 1e-6;
constexpr double kTurnTol = 1e-9;

// An edge by its two corners' indices, in either order.
uint64_t edgeKey(int a, int b) { return uint64_t(uint32_t(std::min(a, b))) << 32 | uint32_t(std::max(a, b)); }

// The unit normal of triangle (a, b, c), counter-clockwise; false when it has no area.
bool unitNormal(const D3& a, const D3& b, const D3& c, D3& n) {
  n = crossd(sub(b, a), sub(c, a));
  const double len = lend(n);
  if (!(len > 0) || !std::isfinite(len)) return false;
  n = {n.x / len, n.y / len, n.z / len};
  return true;
}

// Whether triangle (a, b, c) lies in the plane dot(n, x) = off (n unit), facing either way:
// its normal within kNormalTol of n's, its corners within tol of the plane.
bool inPlane(const D3& n, double off, double tol, const D3& a, const D3& b, const D3& c) {
  const D3 un = crossd(sub(b, a), sub(c, a));
  const double ul = lend(un);
  return ul > 0 && std::fabs(dotd(un, n)) / ul >= 1 - kNormalTol && std::fabs(dotd(n, a) - off) <= tol &&
         std::fabs(dotd(n, b) - off) <= tol && std::fabs(dotd(n, c) - off) <= tol;
}

// Calls f(u) for each triangle u other than t that shares an edge with t (by corner index);
// edgeTris holds (edgeKey, triangle) for every triangle's edges, sorted.
template <class F>
void forEachNeighbour(const std::vector<std::pair<uint64_t, uint32_t>>& edgeTris,
                      const std::vector<std::array<int, 3>>& tri, uint32_t t, const F& f) {
  for (int k = 0; k < 3; ++k) {
    const uint64_t e = edgeKey(tri[t][k], tri[t][(k + 1) % 3]);
    for (auto it = std::lower_bound(edgeTris.begin(), edgeTris.end(), std::make_pair(e, 0u));
         it != edgeTris.end() && it->first == e; ++it)
      if (it->second != t) f(it->second);
  }
}

}  // namespace

// Whether a mesh bounds a solid: its corners welded by position, every edge joins two
// triangles (closed), or one triangle along a boundary that lies in one plane (open there:
// a box standing on the floor without its bottom, as the Cornell box's blocks are), whose
// plane then closes it. Edges of three triangles or more, or a boundary off one plane: not
// a solid (`solid` false).
PlanarFaces::Solid PlanarFaces::solidOf(const Mesh& m) {
  Solid s;
  const auto& v = m.positions;
  // Only convex meshes are asked (Scene::isConvex), which are tested up to 4096 triangles.
  if (m.triangles.empty() || m.triangles.size() > 4096) return s;
  std::vector<std::pair<std::array<float, 3>, int>> at(v.size());
  for (size_t i = 0; i < v.size(); ++i) at[i] = {{v[i].x, v[i].y, v[i].z}, int(i)};
  std::sort(at.begin(), at.end());
  std::vector<int> weld(v.size());
  for (size_t i = 0, id = 0; i < at.size(); ++i) {
    if (i > 0 && at[i].first != at[i - 1].first) ++id;
    weld[size_t(at[i].second)] = int(id);
  }
  std::vector<uint64_t> edges;
  edges.reserve(3 * m.triangles.size());
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = weld[size_t(t[k])], b = weld[size_t(t[(k + 1) % 3])];
      if (a == b) return s;  // a degenerate triangle
      edges.push_back(edgeKey(a, b));
    }
  std::sort(edges.begin(), edges.end());
  std::vector<int> rim;  // welded corners on the boundary
  for (size_t k = 0; k < edges.size();) {
    size_t e = k;
    while (e < edges.size() && edges[e] == edges[k]) ++e;
    if (e - k > 2) return s;
    if (e - k == 1) {
      rim.push_back(int(edges[k] >> 32));
      rim.push_back(int(edges[k] & 0xffffffffu));
    }
    k = e;
  }
  s.solid = true;
  if (rim.empty()) return s;
  // The boundary's plane, from its corners (welded ids back to positions).
  std::vector<char> onRim(at.size(), 0);
  for (int r : rim) onRim[size_t(r)] = 1;
  std::vector<D3> corners;
  for (size_t i = 0; i < at.size(); ++i)
    if (onRim[size_t(weld[size_t(at[i].second)])] && (i == 0 || at[i].first != at[i - 1].first))
      corners.push_back(d3(v[size_t(at[i].second)]));
  D3 n{0, 0, 0};
  double big = 0;
  for (size_t i = 1; i + 1 < corners.size(); ++i) {
    const D3 c = crossd(sub(corners[i], corners[0]), sub(corners[i + 1], corners[0]));
    if (lend(c) > lend(n)) n = c;
  }
  for (const D3& c : corners) big = std::max({big, std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
  const double len = lend(n);
  if (!(len > 0)) {
    s.solid = false;
    return s;
  }
  n = {n.x / len, n.y / len, n.z / len};
  const double off = dotd(n, corners[0]);
  double thick = 0;
  for (const D3& c : corners) thick = std::max(thick, std::fabs(dotd(n, c) - off));
  if (thick > kPlaneTol * 1e3 * big) {  // the boundary does not lie in one plane
    s.solid = false;
    return s;
  }
  // A flat mesh (its boundary's plane holds every corner) bounds nothing.
  bool flat = true;
  for (size_t i = 0; i < v.size() && flat; ++i) flat = std::fabs(dotd(n, d3(v[i])) - off) <= 2 * thick + 1e-6 * big;
  if (flat) {
    s.solid = false;
    return s;
  }
  s.open = true;
  s.opening.normal = Vec3(float(n.x), float(n.y), float(n.z));
  s.opening.offset = float(off);
  s.opening.thickness = float(thick + 1e-6 * big);
  return s;
}

// Whole coplanar regions that are convex become one face each, before the greedy growth
// (which cannot grow a grid of squares past a strip: every triangle added to a rectangle's
// side makes a notch). A region, coplanar triangles joined across shared edges, is one face
// when its triangles cover its convex hull exactly: every edge is shared by at most two of
// them (no overlaps), every edge of one lies on the hull's outline (no holes), and their
// areas add up to the hull's.
void PlanarFaces::convexRegions(const Mesh& m, const std::vector<std::pair<uint64_t, uint32_t>>& edgeTris,
                                size_t base) {
  const auto& tri = m.triangles;
  const auto& v = m.positions;
  std::vector<char> seen(tri.size(), 0);
  std::vector<uint32_t> region, stack;
  std::vector<uint64_t> keys;
  std::vector<int> verts;
  struct P2 {
    double u, v;
    int index;
  };
  std::vector<P2> pts, hull;
  for (uint32_t seed = 0; seed < tri.size(); ++seed) {
    if (seen[seed] || triFace_[base + seed] >= 0) continue;
    seen[seed] = 1;
    const D3 a = d3(v[size_t(tri[seed][0])]);
    D3 n;
    if (!unitNormal(a, d3(v[size_t(tri[seed][1])]), d3(v[size_t(tri[seed][2])]), n)) continue;
    const double off = dotd(n, a);
    const double big = std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)});
    region.assign({seed});
    stack.assign({seed});
    double extent = 0;
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      forEachNeighbour(edgeTris, tri, t, [&](uint32_t u) {
        if (seen[u] || triFace_[base + u] >= 0) return;
        const D3 ua = d3(v[size_t(tri[u][0])]), ub = d3(v[size_t(tri[u][1])]), uc = d3(v[size_t(tri[u][2])]);
        extent = std::max({extent, lend(sub(ub, ua)), lend(sub(uc, ua))});
        if (!inPlane(n, off, kPlaneTol * (extent + big), ua, ub, uc)) return;
        seen[u] = 1;
        region.push_back(u);
        stack.push_back(u);
      });
    }
    if (region.size() < 3) continue;  // one or two triangles: the growth does as well
    // Edges: interior ones shared by two, outline ones by one, none by more.
    keys.clear();
    for (uint32_t t : region)
      for (int k = 0; k < 3; ++k) keys.push_back(edgeKey(tri[t][k], tri[t][(k + 1) % 3]));
    std::sort(keys.begin(), keys.end());
    // The hull, in the plane's coordinates (u along an edge, w = n x u).
    D3 bu = sub(d3(v[size_t(tri[seed][1])]), a);
    bu = {bu.x / lend(bu), bu.y / lend(bu), bu.z / lend(bu)};
    const D3 bw = crossd(n, bu);
    verts.clear();
    for (uint32_t t : region)
      for (int k = 0; k < 3; ++k) verts.push_back(tri[t][k]);
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    pts.clear();
    for (int i : verts) {
      const D3 x = sub(d3(v[size_t(i)]), a);
      pts.push_back({dotd(x, bu), dotd(x, bw), i});
    }
    std::sort(pts.begin(), pts.end(), [](const P2& p, const P2& q) { return p.u < q.u || (p.u == q.u && p.v < q.v); });
    auto turn = [](const P2& o, const P2& p, const P2& q) { return (p.u - o.u) * (q.v - o.v) - (p.v - o.v) * (q.u - o.u); };
    hull.assign(2 * pts.size(), P2{});
    size_t h = 0;
    for (size_t i = 0; i < pts.size(); ++i) {  // Andrew's monotone chain, counter-clockwise
      while (h >= 2 && turn(hull[h - 2], hull[h - 1], pts[i]) <= 0) --h;
      hull[h++] = pts[i];
    }
    for (size_t i = pts.size() - 1, lower = h + 1; i-- > 0;) {
      while (h >= lower && turn(hull[h - 2], hull[h - 1], pts[i]) <= 0) --h;
      hull[h++] = pts[i];
    }
    hull.resize(h > 0 ? h - 1 : 0);
    if (hull.size() < 3 || int(hull.size()) > kMaxCorners) continue;
    double hullArea = 0, area = 0;
    for (size_t i = 0; i < hull.size(); ++i) {
      const P2 &p = hull[i], &q = hull[(i + 1) % hull.size()];
      hullArea += p.u * q.v - q.u * p.v;
    }
    hullArea *= 0.5;
    for (uint32_t t : region) area += 0.5 * lend(crossd(sub(d3(v[size_t(tri[t][1])]), d3(v[size_t(tri[t][0])])),
                                                          sub(d3(v[size_t(tri[t][2])]), d3(v[size_t(tri[t][0])]))));
    if (!(std::fabs(area - hullArea) <= 1e-7 * hullArea)) continue;
    // Every outline edge on the hull's outline: its midpoint within tol of a hull edge.
    const double tol = kPlaneTol * (extent + big);
    bool covered = true;
    for (size_t k = 0; k < keys.size() && covered;) {
      size_t e = k;
      while (e < keys.size() && keys[e] == keys[k]) ++e;
      if (e - k > 2) covered = false;
      if (e - k == 1) {
        const D3 e0 = sub(d3(v[size_t(keys[k] >> 32)]), a), e1 = sub(d3(v[size_t(keys[k] & 0xffffffffu)]), a);
        const P2 mp{0.5 * (dotd(e0, bu) + dotd(e1, bu)), 0.5 * (dotd(e0, bw) + dotd(e1, bw)), -1};
        bool onHull = false;
        for (size_t i = 0; i < hull.size() && !onHull; ++i) {
          const P2 &p = hull[i], &q = hull[(i + 1) % hull.size()];
          const double el = std::hypot(q.u - p.u, q.v - p.v);
          onHull = el > 0 && std::fabs(turn(p, q, mp)) / el <= tol;
        }
        covered = onHull;
      }
      k = e;
    }
    if (!covered) continue;
    std::vector<D3> corners;
    for (const P2& p : hull) corners.push_back(d3(v[size_t(p.index)]));
    double thick = 0;
    for (int i : verts) thick = std::max(thick, std::fabs(dotd(n, d3(v[size_t(i)])) - off));
    const int face = int(faces_.size());
    for (uint32_t t : region) triFace_[base + t] = face;
    addFace(corners, n, off, thick);
  }
}

PlanarFaces::PlanarFaces(const std::vector<Shape>& shapes, const std::vector<Mesh>& meshes) {
  firstTriangle_.assign(shapes.size(), -1);
  size_t total = 0;
  for (const Shape& s : shapes)
    if (s.kind == io::ShapeKind::Mesh) total += meshes[size_t(s.mesh)].triangles.size();
  const bool meshFaces = total <= kMaxTriangles;
  if (meshFaces) {
    triFace_.reserve(total);
    solids_.resize(shapes.size());
  }
  std::vector<std::pair<uint64_t, uint32_t>> edgeTris;  // (vertex pair, triangle), sorted
  std::vector<uint32_t> stack, members;
  std::vector<int> poly;
  std::vector<D3> corners;
  for (size_t si = 0; si < shapes.size(); ++si) {
    if (shapes[si].kind != io::ShapeKind::Mesh || !meshFaces) continue;
    const Mesh& m = meshes[size_t(shapes[si].mesh)];
    const auto& tri = m.triangles;
    const auto& v = m.positions;
    firstTriangle_[si] = int64_t(triFace_.size());
    const size_t base = triFace_.size();
    triFace_.resize(base + tri.size(), -1);
    edgeTris.clear();
    for (uint32_t t = 0; t < tri.size(); ++t)
      for (int k = 0; k < 3; ++k) edgeTris.push_back({edgeKey(tri[t][k], tri[t][(k + 1) % 3]), t});
    std::sort(edgeTris.begin(), edgeTris.end());
    Solid solid = solidOf(m);
    solid.faceBegin = uint32_t(faces_.size());
    auto pushNeighbours = [&](uint32_t t) {
      forEachNeighbour(edgeTris, tri, t, [&](uint32_t u) {
        if (triFace_[base + u] < 0) stack.push_back(u);
      });
    };
    convexRegions(m, edgeTris, base);
    for (uint32_t seed = 0; seed < tri.size(); ++seed) {
      if (triFace_[base + seed] >= 0) continue;
      const D3 a = d3(v[size_t(tri[seed][0])]), b = d3(v[size_t(tri[seed][1])]), c = d3(v[size_t(tri[seed][2])]);
      D3 n;
      if (!unitNormal(a, b, c, n)) continue;  // degenerate: no face
      const double off = dotd(n, a);
      double extent = std::max({lend(sub(b, a)), lend(sub(c, a)), lend(sub(c, b))});
      const int face = int(faces_.size());
      poly.assign({tri[seed][0], tri[seed][1], tri[seed][2]});
      members.assign({seed});
      triFace_[base + seed] = face;
      stack.clear();
      pushNeighbours(seed);
      while (!stack.empty() && int(poly.size()) < kMaxCorners) {
        const uint32_t u = stack.back();
        stack.pop_back();
        if (triFace_[base + u] >= 0) continue;
        const D3 ua = d3(v[size_t(tri[u][0])]), ub = d3(v[size_t(tri[u][1])]), uc = d3(v[size_t(tri[u][2])]);
        if (!inPlane(n, off, kPlaneTol * (extent + std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)})), ua,
                     ub, uc))
          continue;
        // The edge u shares with the polygon's boundary, and u's corner across it.
        bool joined = false;
        for (int k = 0; k < 3 && !joined; ++k) {
          const int i = tri[u][k], j = tri[u][(k + 1) % 3], w = tri[u][(k + 2) % 3];
          const size_t np = poly.size();
          for (size_t q = 0; q < np; ++q) {
            const int P = poly[q], Q = poly[(q + 1) % np];
            if (!((P == i && Q == j) || (P == j && Q == i))) continue;
            const D3 p = d3(v[size_t(P)]), qv = d3(v[size_t(Q)]), wv = d3(v[size_t(w)]);
            const D3 prev = d3(v[size_t(poly[(q + np - 1) % np])]), next = d3(v[size_t(poly[(q + 2) % np])]);
            // Interior is to the left of each edge (counter-clockwise about n): w must lie
            // strictly to the right of P->Q, and the corners at P and Q stay convex.
            const D3 pq = sub(qv, p), pw = sub(wv, p);
            const double side = dotd(n, crossd(pq, pw));
            if (!(side < -kTurnTol * lend(pq) * lend(pw))) break;
            const D3 e0 = sub(p, prev), e1 = sub(wv, p), e2 = sub(qv, wv), e3 = sub(next, qv);
            if (dotd(n, crossd(e0, e1)) < -kTurnTol * lend(e0) * lend(e1)) break;
            if (dotd(n, crossd(e2, e3)) < -kTurnTol * lend(e2) * lend(e3)) break;
            poly.insert(poly.begin() + long(q + 1), w);
            joined = true;
            break;
          }
        }
        if (!joined) continue;
        triFace_[base + u] = face;
        members.push_back(u);
        extent = std::max({extent, lend(sub(ub, ua)), lend(sub(uc, ua)), lend(sub(uc, ub))});
        pushNeighbours(u);
      }
      // Corners on a straight edge add nothing: drop them.
      for (size_t q = 0; q < poly.size() && poly.size() > 3;) {
        const size_t np = poly.size();
        const D3 p = d3(v[size_t(poly[q])]);
        const D3 e0 = sub(p, d3(v[size_t(poly[(q + np - 1) % np])])), e1 = sub(d3(v[size_t(poly[(q + 1) % np])]), p);
        if (std::fabs(dotd(n, crossd(e0, e1))) <= kTurnTol * lend(e0) * lend(e1))
          poly.erase(poly.begin() + long(q));
        else
          ++q;
      }
      double thick = 0;
      for (uint32_t t : members)
        for (int k = 0; k < 3; ++k) thick = std::max(thick, std::fabs(dotd(n, d3(v[size_t(tri[t][k])])) - off));
      corners.clear();
      for (int q : poly) corners.push_back(d3(v[size_t(q)]));
      addFace(corners, n, off, thick);
    }
    // A solid's faces get their normals turned outward: away from the corners' mean, which
    // a convex solid holds inside.
    solid.faceEnd = uint32_t(faces_.size());
    if (solid.solid) {
      D3 mean{0, 0, 0};
      for (const Vec3& x : v) mean = {mean.x + x.x, mean.y + x.y, mean.z + x.z};
      mean = {mean.x / double(v.size()), mean.y / double(v.size()), mean.z / double(v.size())};
      auto outward = [&](Face& f) {
        if (dotd(d3(f.normal), mean) - f.offset > 0) {
          f.normal = -f.normal;
          f.offset = -f.offset;
        }
      };
      for (uint32_t k = solid.faceBegin; k < solid.faceEnd; ++k) outward(faces_[k]);
      if (solid.open) outward(solid.opening);
    }
    solids_[si] = solid;
  }
  // Squares: one face each, the unit square z = 0, |x|, |y| <= 1/2, in the world.
  squareFace_.assign(shapes.size(), -1);
  for (size_t si = 0; si < shapes.size(); ++si) {
    if (shapes[si].kind != io::ShapeKind::Square) continue;
    corners.clear();
    for (const Vec3 c : {Vec3(-0.5f, -0.5f, 0), Vec3(0.5f, -0.5f, 0), Vec3(0.5f, 0.5f, 0), Vec3(-0.5f, 0.5f, 0)})
      corners.push_back(d3(shapes[si].toWorld.point(c)));
    D3 n;
    if (!unitNormal(corners[0], corners[1], corners[2], n)) continue;
    squareFace_[si] = int(faces_.size());
    addFace(corners, n, dotd(n, corners[0]), 0);
  }
}

// A face from its corners, counter-clockwise about the unit normal n, on the plane
// dot(n, x) = off, its corners up to `thick` off it.
void PlanarFaces::addFace(const std::vector<D3>& corners, const D3& n, double off, double thick) {
  Face f;
  f.normal = Vec3(float(n.x), float(n.y), float(n.z));
  f.offset = float(off);
  double big = 0;
  for (const D3& x : corners) {
    f.box.extend(Vec3(float(x.x), float(x.y), float(x.z)));
    thick = std::max(thick, std::fabs(dotd(n, x) - off));
    big = std::max({big, std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  }
  // The float plane and edges round at about 1e-7 of the coordinates: counted in.
  f.thickness = float(thick + 1e-6 * big);
  f.edgeBegin = uint32_t(edges_.size());
  f.edgeCount = uint32_t(corners.size());
  for (size_t q = 0; q < corners.size(); ++q) {
    const D3 &p = corners[q], &qv = corners[(q + 1) % corners.size()];
    D3 in = crossd(n, sub(qv, p));
    const double il = lend(in);
    in = {in.x / il, in.y / il, in.z / il};
    edges_.push_back({Vec3(float(in.x), float(in.y), float(in.z)), float(dotd(in, p))});
  }
  faces_.push_back(f);
}

bool PlanarFaces::nearCrossingsInside(const Face& f, const Vec3& p, float sp, const Vec3* dirs, int n,
                                      float mg) const {
  const Edge* e = &edges_[f.edgeBegin];
  for (int i = 0; i < n; ++i) {
    const float along = dot(f.normal, dirs[i]);
    if (!(sp * along < 0)) return false;  // parallel, or leaving the plane: no crossing
    const Vec3 x = p + dirs[i] * (std::fabs(sp) / std::fabs(along));
    for (uint32_t k = 0; k < f.edgeCount; ++k)
      if (!(dot(e[k].inward, x) - e[k].at > -mg)) return false;
  }
  return true;
}

int PlanarFaces::crossesAll(int face, const Vec3& p, const Vec3* dirs, int n, float tMax, float margin) const {
  const Face& f = faces_[size_t(face)];
  const float mg = margin + f.thickness;
  const float sp = dot(f.normal, p) - f.offset;
  // A point within the margin of the plane beside the face (on a neighbouring triangle of a
  // bumpy surface) is not proven: rays would prove it rarely, at up to eight each (a
  // 200k-triangle terrain sent 1.3 probe rays per shadow ray and rendered 13-30% slower).
  // But where every segment crosses the plane within the margin of the face (a point on a
  // wall a centimetre behind a window mesh, or at the foot of a wall, looking through it),
  // the rays often prove the cluster hidden, and are asked (-1): answering 0 there costs
  // the rooms 5.5% more shadow rays per point and the church 2.7% (128², --reconstruct 4),
  // while on the terrain these rays are 0.5% of all.
  if (!(std::fabs(sp) > mg)) return nearCrossingsInside(f, p, sp, dirs, n, mg) ? -1 : 0;
  const float toward = sp > 0 ? -1.0f : 1.0f;
  float cosMin = 1;
  for (int i = 0; i < n; ++i) cosMin = std::min(cosMin, toward * dot(f.normal, dirs[i]));
  // Grazing (or away from the plane): the inset would be huge; not proven.
  if (!(cosMin > 0.02f)) return 0;
  const float slide = mg / cosMin;
  const float inset = mg + slide;
  const Edge* e = &edges_[f.edgeBegin];
  for (int i = 0; i < n; ++i) {
    const float t = std::fabs(sp) / (toward * dot(f.normal, dirs[i]));
    if (!(t > mg) || !(t + slide < tMax - mg)) return 0;
    const Vec3 x = p + dirs[i] * t;
    for (uint32_t k = 0; k < f.edgeCount; ++k)
      if (!(dot(e[k].inward, x) - e[k].at > inset)) return 0;
  }
  return 1;
}

int PlanarFaces::solidMeetsAll(int shape, const Vec3& p, const Vec3* dirs, int n, float tMax, float margin) const {
  if (size_t(shape) >= solids_.size()) return -1;
  const Solid& s = solids_[size_t(shape)];
  if (s.faceEnd == s.faceBegin) return -1;
  // A flat convex mesh of one face: proven by the face where it can be, else by the rays, as
  // all its probes were while it was split into several faces (before whole regions made
  // many such meshes one face, the rooms' shadow rays per point at 128², --reconstruct 4
  // were 342; after, with 0 for "not proven", 382; with the rays, 359). Faces of non-convex
  // meshes keep their 0: sending those to the rays as well saved the rooms another 5% but
  // cost the terrain 7% (47k probe rays for 4,096 points).
  if (!s.solid) {
    if (s.faceEnd - s.faceBegin != 1) return -1;
    return crossesAll(int(s.faceBegin), p, dirs, n, tMax, margin) == 1 ? 1 : -1;
  }
  const uint32_t planes = s.faceEnd - s.faceBegin + (s.open ? 1 : 0);
  auto plane = [&](uint32_t k) -> const Face& { return k < s.faceEnd - s.faceBegin ? faces_[s.faceBegin + k] : s.opening; };
  // From outside the solid grown by the margin only (a segment from inside crosses no face).
  bool outside = false;
  for (uint32_t k = 0; k < planes && !outside; ++k) {
    const Face& f = plane(k);
    outside = dot(f.normal, p) - f.offset > margin + f.thickness;
  }
  if (!outside) return -1;
  // Each segment, clipped by every face's plane moved inward by the margin (and the face's
  // thickness), must keep a piece between the margin past p and the margin before tMax.
  // Through an open solid it must also leave before tMax: it then crosses the boundary twice,
  // in two planes, and the opening lies in one.
  for (int i = 0; i < n; ++i) {
    float tIn = margin, tOut = kInf;
    for (uint32_t k = 0; k < planes && tIn < tOut; ++k) {
      const Face& f = plane(k);
      const float room = f.offset - margin - f.thickness - dot(f.normal, p);
      const float along = dot(f.normal, dirs[i]);
      if (along > 0) {
        tOut = std::min(tOut, room / along);
      } else if (along < 0) {
        tIn = std::max(tIn, room / along);
      } else if (room < 0) {
        return 0;
      }
    }
    if (!(tIn < std::min(tOut, tMax - margin))) return 0;
    if (s.open && !(tOut < tMax - margin)) return 0;
  }
  return 1;
}

}  // namespace lc::scene
