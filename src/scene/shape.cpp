#include "scene/shape.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace lc::scene {

namespace {

using io::ShapeKind;

// Keeps the smallest root in (tmin, tmax).
struct Closest {
  double tmin, tmax;
  double t;
  int part = -1;
  Closest(double lo, double hi) : tmin(lo), tmax(hi), t(hi) {}
  void offer(double tc, int p) {
    if (tc > tmin && tc < t) {
      t = tc;
      part = p;
    }
  }
};

// Roots of a t^2 + b t + c = 0 in a numerically stable form; false if none.
bool solveQuadratic(double a, double b, double c, double& t0, double& t1) {
  if (a == 0) {
    if (b == 0) return false;
    t0 = t1 = -c / b;
    return true;
  }
  double disc = b * b - 4 * a * c;
  if (disc < 0) return false;
  double s = std::sqrt(disc);
  double q = b < 0 ? -0.5 * (b - s) : -0.5 * (b + s);
  t0 = q / a;
  t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// Watertight rims (issue 29): the side and a cap of a cylinder or cone are separate tests,
// and a ray through the rim itself could fail both by a rounding error each (z just above
// the side's end, x^2 + y^2 just outside the disk) and pass between them. Both parts reach
// this far past the rim, far above double rounding and far below anything visible.
constexpr double kRimSlack = 1e-9;

// A disk of radius r in the plane z = z0.
void offerDisk(Closest& c, const double o[3], const double d[3], double z0, double r, int part) {
  if (d[2] == 0 || r <= 0) return;
  double t = (z0 - o[2]) / d[2];
  double x = o[0] + t * d[0], y = o[1] + t * d[1];
  if (x * x + y * y <= r * r * (1 + kRimSlack)) c.offer(t, part);
}

}  // namespace

bool intersectQuadric(const Shape& s, const Vec3& of, const Vec3& df, float tmin, float tmax,
                      float& tOut, int& partOut) {
  const double o[3] = {of.x, of.y, of.z};
  const double d[3] = {df.x, df.y, df.z};
  Closest c(tmin, tmax);
  switch (s.kind) {
    case ShapeKind::Sphere: {
      double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      double b = 2 * (o[0] * d[0] + o[1] * d[1] + o[2] * d[2]);
      double cc = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1;
      double t0, t1;
      if (solveQuadratic(a, b, cc, t0, t1)) {
        c.offer(t0, 0);
        c.offer(t1, 0);
      }
      break;
    }
    case ShapeKind::Box: {
      // Slabs: the entry face is the last axis to be entered, the exit face the first left.
      double tNear = -INFINITY, tFar = INFINITY;
      int nearPart = -1, farPart = -1;
      for (int i = 0; i < 3; ++i) {
        if (d[i] == 0) {
          if (o[i] < -0.5 || o[i] > 0.5) return false;
          continue;
        }
        double inv = 1.0 / d[i];
        double ta = (-0.5 - o[i]) * inv, tb = (0.5 - o[i]) * inv;
        int pa = 2 * i, pb = 2 * i + 1;  // -face, +face
        if (ta > tb) {
          std::swap(ta, tb);
          std::swap(pa, pb);
        }
        if (ta > tNear) { tNear = ta; nearPart = pa; }
        if (tb < tFar) { tFar = tb; farPart = pb; }
      }
      if (tNear > tFar) return false;
      if (nearPart >= 0) c.offer(tNear, nearPart);
      if (farPart >= 0) c.offer(tFar, farPart);
      break;
    }
    case ShapeKind::Square: {
      if (d[2] == 0) return false;
      double t = -o[2] / d[2];
      double x = o[0] + t * d[0], y = o[1] + t * d[1];
      if (std::fabs(x) <= 0.5 && std::fabs(y) <= 0.5) c.offer(t, 0);
      break;
    }
    case ShapeKind::Cylinder: {
      double a = d[0] * d[0] + d[1] * d[1];
      double b = 2 * (o[0] * d[0] + o[1] * d[1]);
      double cc = o[0] * o[0] + o[1] * o[1] - 1;
      double t0, t1;
      if (a > 0 && solveQuadratic(a, b, cc, t0, t1)) {
        for (double t : {t0, t1}) {
          double z = o[2] + t * d[2];
          if (z >= -kRimSlack && z <= 1 + kRimSlack) c.offer(t, 0);
        }
      }
      if (s.capped) {
        offerDisk(c, o, d, 0, 1, 1);
        offerDisk(c, o, d, 1, 1, 2);
      }
      break;
    }
    case ShapeKind::Cone: {
      double h = s.height, r0 = s.bottomRadius, r1 = s.topRadius;
      if (h <= 0) return false;
      double k = (r1 - r0) / h;
      // x^2 + y^2 = (r0 + k z)^2
      double rz0 = r0 + k * o[2];
      double a = d[0] * d[0] + d[1] * d[1] - k * k * d[2] * d[2];
      double b = 2 * (o[0] * d[0] + o[1] * d[1] - k * rz0 * d[2]);
      double cc = o[0] * o[0] + o[1] * o[1] - rz0 * rz0;
      double t0, t1;
      if (solveQuadratic(a, b, cc, t0, t1)) {
        for (double t : {t0, t1}) {
          double z = o[2] + t * d[2];
          // The quadric is a double cone: keep the nappe where the radius is non-negative
          // (the nappes meet at the apex, where the slack makes no difference).
          double slack = kRimSlack * h;
          if (z >= -slack && z <= h + slack && r0 + k * z >= -kRimSlack * std::max(std::fabs(r0), std::fabs(r1)))
            c.offer(t, 0);
        }
      }
      if (s.capped) {
        offerDisk(c, o, d, 0, r0, 1);
        offerDisk(c, o, d, h, r1, 2);
      }
      break;
    }
    case ShapeKind::Mesh:
      return false;
  }
  if (c.part < 0) return false;
  tOut = float(c.t);
  partOut = c.part;
  // Rounding to float must keep t inside the open interval the caller asked for.
  return tOut > tmin && tOut < tmax;
}

Vec3 quadricLocalNormal(const Shape& s, const Vec3& p, int part) {
  switch (s.kind) {
    case ShapeKind::Sphere: return p;
    case ShapeKind::Box: {
      Vec3 n(0, 0, 0);
      n[part / 2] = (part % 2) ? 1.0f : -1.0f;
      return n;
    }
    case ShapeKind::Square: return Vec3(0, 0, 1);
    case ShapeKind::Cylinder:
      if (part == 1) return Vec3(0, 0, -1);
      if (part == 2) return Vec3(0, 0, 1);
      return Vec3(p.x, p.y, 0);
    case ShapeKind::Cone: {
      if (part == 1) return Vec3(0, 0, -1);
      if (part == 2) return Vec3(0, 0, 1);
      float k = (s.topRadius - s.bottomRadius) / s.height;
      float r = s.bottomRadius + k * p.z;
      // Gradient of x^2 + y^2 - (r0 + k z)^2.
      return Vec3(p.x, p.y, -k * r);
    }
    case ShapeKind::Mesh: break;
  }
  return Vec3(0, 0, 1);
}

static float angleU(const Vec3& p) {
  float u = std::atan2(p.y, p.x) / (2 * kPi);
  return u < 0 ? u + 1 : u;
}

Vec2 quadricUv(const Shape& s, const Vec3& p, int part) {
  switch (s.kind) {
    case ShapeKind::Sphere: {
      float z = std::clamp(p.z / std::max(length(p), 1e-20f), -1.0f, 1.0f);
      return Vec2(angleU(p), 0.5f + std::asin(z) / kPi);
    }
    case ShapeKind::Box: {
      // (u, v) right-handed about each face's outward normal, so no face shows its texture
      // mirrored: x faces (+-y, z), y faces (-+x, z), z faces (+-x, y).
      switch (part) {
        case 0: return Vec2(0.5f - p.y, p.z + 0.5f);  // -x
        case 1: return Vec2(p.y + 0.5f, p.z + 0.5f);  // +x
        case 2: return Vec2(p.x + 0.5f, p.z + 0.5f);  // -y
        case 3: return Vec2(0.5f - p.x, p.z + 0.5f);  // +y
        case 4: return Vec2(0.5f - p.x, p.y + 0.5f);  // -z
        default: return Vec2(p.x + 0.5f, p.y + 0.5f);  // +z
      }
    }
    case ShapeKind::Square: return Vec2(p.x + 0.5f, p.y + 0.5f);
    case ShapeKind::Cylinder:
    case ShapeKind::Cone: {
      float h = s.kind == ShapeKind::Cylinder ? 1.0f : s.height;
      if (part == 0) return Vec2(angleU(p), p.z / h);
      float r = s.kind == ShapeKind::Cylinder ? 1.0f : (part == 1 ? s.bottomRadius : s.topRadius);
      if (r <= 0) r = 1;
      return Vec2((p.x / r + 1) * 0.5f, (p.y / r + 1) * 0.5f);
    }
    case ShapeKind::Mesh: break;
  }
  return Vec2(0, 0);
}

Bounds3 quadricLocalBounds(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::Sphere: return Bounds3(Vec3(-1, -1, -1), Vec3(1, 1, 1));
    case ShapeKind::Box: return Bounds3(Vec3(-0.5f), Vec3(0.5f));
    case ShapeKind::Square: return Bounds3(Vec3(-0.5f, -0.5f, 0), Vec3(0.5f, 0.5f, 0));
    case ShapeKind::Cylinder: return Bounds3(Vec3(-1, -1, 0), Vec3(1, 1, 1));
    case ShapeKind::Cone: {
      float r = std::max(std::fabs(s.bottomRadius), std::fabs(s.topRadius));
      return Bounds3(Vec3(-r, -r, 0), Vec3(r, r, s.height));
    }
    case ShapeKind::Mesh: break;
  }
  return {};
}

Bounds3 quadricBounds(const Shape& s) {
  if (s.kind == ShapeKind::Mesh) return {};
  const Bounds3 local = quadricLocalBounds(s);
  Bounds3 world;
  for (int i = 0; i < 8; ++i) {
    Vec3 c((i & 1) ? local.hi.x : local.lo.x, (i & 2) ? local.hi.y : local.lo.y,
           (i & 4) ? local.hi.z : local.lo.z);
    world.extend(s.toWorld.point(c));
  }
  // Pad for float rounding in the transform so Embree never culls a true hit.
  Vec3 pad = (vabs(world.lo) + vabs(world.hi) + world.extent()) * 1e-6f;
  world.lo -= pad;
  world.hi += pad;
  return world;
}

namespace {

// Narrows [t0, t1] to where a t^2 + 2 b t + c < 0 (a > 0); whether any of it is left.
bool insideQuadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - a * c;
  if (!(disc > 0)) return false;
  const double q = std::sqrt(disc);
  t0 = std::max(t0, (-b - q) / a);
  t1 = std::min(t1, (-b + q) / a);
  return t0 < t1;
}

}  // namespace

SolidWithMargin::SolidWithMargin(const Shape& s, float margin) : s_(s), m_(double(margin)) {
  decides_ = canProveMeets(s) && margin >= 0;
  // A world displacement of length m moves local coordinate i by at most m times the norm
  // of row i of toLocal, and the local point by at most m times the Frobenius norm.
  double f2 = 0;
  for (int i = 0; i < 3; ++i) {
    const auto& r = s.toLocal.m[size_t(i)];
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    row_[i] = std::sqrt(r2);
    f2 += r2;
  }
  radial_ = std::sqrt(row_[0] * row_[0] + row_[1] * row_[1]);
  frobenius_ = std::sqrt(f2);
}

void SolidWithMargin::toLocal(const Vec3& p, double* x) const {
  for (int i = 0; i < 3; ++i) {
    const auto& r = s_.toLocal.m[size_t(i)];
    x[i] = r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3];
  }
}

bool SolidWithMargin::surelyOutside(const Vec3& p) const {
  if (!decides_) return false;
  double x[3];
  toLocal(p, x);
  switch (s_.kind) {
    case io::ShapeKind::Box:
      for (int i = 0; i < 3; ++i)
        if (std::fabs(x[i]) > 0.5 + m_ * row_[i] + 1e-6) return true;
      return false;
    case io::ShapeKind::Cylinder: {
      const double grow = m_ * radial_ + 1e-6, zGrow = m_ * row_[2] + 1e-6;
      return x[0] * x[0] + x[1] * x[1] > (1 + grow) * (1 + grow) || x[2] < -zGrow || x[2] > 1 + zGrow;
    }
    default: {
      const double R = 1 + m_ * frobenius_ + 1e-6;
      return x[0] * x[0] + x[1] * x[1] + x[2] * x[2] > R * R;
    }
  }
}

bool SolidWithMargin::surelyMeets(const Vec3& of, const Vec3& df, float tLo, float tHi) const {
  if (!decides_ || !(tLo <= tHi)) return false;
  double o[3], d[3];
  toLocal(of, o);
  for (int i = 0; i < 3; ++i) {
    const auto& r = s_.toLocal.m[size_t(i)];
    d[i] = r[0] * df.x + r[1] * df.y + r[2] * df.z;
  }
  double t0 = tLo, t1 = tHi;
  if (s_.kind == io::ShapeKind::Box) {
    for (int i = 0; i < 3; ++i) {
      const double h = 0.5 - m_ * row_[i] - 1e-6;  // the slab shrunk by the depth
      if (!(h > 0)) return false;
      if (d[i] == 0) {
        if (o[i] <= -h || o[i] >= h) return false;
        continue;
      }
      double ta = (-h - o[i]) / d[i], tb = (h - o[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    return t0 < t1;
  }
  if (s_.kind == io::ShapeKind::Cylinder) {
    // The solid x^2 + y^2 <= 1, 0 <= z <= 1, shrunk: its radius by the depth in x and y
    // together, its height by the depth in z at each cap.
    const double r = 1 - m_ * radial_ - 1e-6;
    const double zLo = m_ * row_[2] + 1e-6, zHi = 1 - zLo;
    if (!(r > 0) || !(zLo < zHi)) return false;
    if (d[2] == 0) {
      if (o[2] <= zLo || o[2] >= zHi) return false;
    } else {
      double ta = (zLo - o[2]) / d[2], tb = (zHi - o[2]) / d[2];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    const double a = d[0] * d[0] + d[1] * d[1];
    const double c = o[0] * o[0] + o[1] * o[1] - r * r;
    if (a == 0) return c < 0 && t0 < t1;  // along the axis: inside the radius throughout
    return insideQuadratic(a, o[0] * d[0] + o[1] * d[1], c, t0, t1);
  }
  // The unit sphere shrunk to radius 1 - depth: |o + t d|^2 < r^2 on an open interval.
  const double r = 1 - m_ * frobenius_ - 1e-6;
  if (!(r > 0)) return false;
  const double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (!(a > 0)) return false;
  return insideQuadratic(a, o[0] * d[0] + o[1] * d[1] + o[2] * d[2], o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - r * r,
                         t0, t1);
}

bool isConvexShape(const Shape& s, const Mesh* mesh) {
  switch (s.kind) {
    case io::ShapeKind::Sphere:
    case io::ShapeKind::Box:
    case io::ShapeKind::Square: return true;
    case io::ShapeKind::Cylinder:
    case io::ShapeKind::Cone: return s.capped;
    case io::ShapeKind::Mesh: break;
  }
  if (!mesh || mesh->triangles.empty() || mesh->triangles.size() > 4096 || mesh->positions.size() > 4096) return false;
  const std::vector<Vec3>& v = mesh->positions;
  Bounds3 b;
  for (const auto& t : mesh->triangles)
    for (int k : t) b.extend(v[size_t(k)]);
  const float tol = 1e-4f * b.diagonal();
  if (!(tol > 0)) return false;
  // Every face's plane must have every vertex on one side: the faces lie on the boundary
  // of the vertices' convex hull.
  double area = 0;
  Vec3 n0(0.0f);
  bool planar = true;
  for (const auto& t : mesh->triangles) {
    const Vec3 &a = v[size_t(t[0])], &b1 = v[size_t(t[1])], &c = v[size_t(t[2])];
    Vec3 n = cross(b1 - a, c - a);
    float len = length(n);
    if (!(len > 0)) continue;
    area += 0.5 * len;
    n = n / len;
    if (length2(n0) == 0) n0 = n;
    bool below = false, above = false;
    for (const auto& u : mesh->triangles)
      for (int k : u) {
        float d = dot(v[size_t(k)] - a, n);
        below |= d < -tol;
        above |= d > tol;
        planar &= std::fabs(dot(v[size_t(k)] - a, n0)) <= tol;
      }
    if (below && above) return false;
  }
  if (length2(n0) == 0) return false;
  if (planar) {
    // A flat mesh is convex when its triangles cover exactly the hull of its vertices.
    Vec3 e1, e2;
    orthonormalBasis(n0, e1, e2);
    std::vector<std::pair<double, double>> pts;
    for (const auto& t : mesh->triangles)
      for (int k : t) pts.emplace_back(dot(v[size_t(k)], e1), dot(v[size_t(k)], e2));
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return false;
    auto cr = [](const std::pair<double, double>& o, const std::pair<double, double>& p,
                 const std::pair<double, double>& q) {
      return (p.first - o.first) * (q.second - o.second) - (p.second - o.second) * (q.first - o.first);
    };
    std::vector<std::pair<double, double>> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {  // Andrew's monotone chain
      while (k >= 2 && cr(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
      h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
      while (k >= t && cr(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
      h[k++] = pts[i];
    }
    double hull = 0;
    for (size_t i = 0; i + 1 < k; ++i) hull += h[i].first * h[i + 1].second - h[i + 1].first * h[i].second;
    hull = 0.5 * std::fabs(hull);
    return hull > 0 && std::fabs(area - hull) <= 1e-3 * hull;
  }
  // A solid: closed, or open along one planar loop (a box without its bottom): a line
  // through the hull cannot enter and leave through one planar opening, so it meets a face.
  // Vertices are welded by position first: meshes often repeat a corner per face.
  std::vector<int> weld(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    weld[i] = int(i);
    for (size_t j = 0; j < i; ++j)
      if (length(v[i] - v[j]) <= tol) {
        weld[i] = weld[j];
        break;
      }
  }
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : mesh->triangles)
    for (int j = 0; j < 3; ++j) {
      int a = weld[size_t(t[size_t(j)])], c = weld[size_t(t[size_t((j + 1) % 3)])];
      if (a != c) ++edges[{std::min(a, c), std::max(a, c)}];
    }
  std::vector<Vec3> open;
  for (const auto& [e, count] : edges) {
    if (count > 2) return false;
    if (count == 1) {
      open.push_back(v[size_t(e.first)]);
      open.push_back(v[size_t(e.second)]);
    }
  }
  if (open.empty()) return true;
  if (open.size() < 6) return false;
  // The opening's points must lie in one plane.
  Vec3 on(0.0f);
  for (size_t i = 2; i < open.size() && length2(on) == 0; ++i) {
    Vec3 c = cross(open[1] - open[0], open[i] - open[0]);
    if (length(c) > tol * tol) on = normalize(c);
  }
  if (length2(on) == 0) return false;
  for (const Vec3& q : open)
    if (std::fabs(dot(q - open[0], on)) > tol) return false;
  return true;
}

}  // namespace lc::scene
