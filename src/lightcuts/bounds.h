// Upper bounds of a light cluster's unshadowed contribution (Walter et al. 2005, sec. 4.1):
//   bound = M_ub * G_ub * I_C  (visibility bounded by 1)
// Every factor is a true upper bound over all lights the cluster may hold: the property
// tests in bounds_test.cpp check that against brute force on random configurations.
#pragma once

#include <cmath>

#include "core/math.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/shading.h"

namespace lc::lightcuts {

// An orthonormal frame whose w axis is the direction of interest, with the absolute
// values of its axes (used to rotate box extents) computed once.
struct Frame {
  Vec3 u, v, w;
  Vec3 au, av, aw;
};
inline Frame makeFrame(const Vec3& w) {
  Frame f;
  f.w = w;
  orthonormalBasis(w, f.u, f.v);
  f.au = vabs(f.u);
  f.av = vabs(f.v);
  f.aw = vabs(f.w);
  return f;
}

// Upper bound of cos(angle(f.w, q)) over all vectors q in the box [lo, hi] (a box of
// vectors from the origin). The box is rotated into the frame and re-bounded (centre
// and |R| times the half extent); then with z the axis: cos <= Mz / sqrt(min x^2 +
// min y^2 + Mz^2), and <= 0 when Mz <= 0 (returned as 0).
inline float cosBoundBox(const Frame& f, const Vec3& lo, const Vec3& hi) {
  Vec3 c = (lo + hi) * 0.5f, h = (hi - lo) * 0.5f;
  float mz = dot(c, f.w) + dot(f.aw, h);
  if (mz <= 0) return 0;
  float cx = dot(c, f.u), hx = dot(f.au, h);
  float cy = dot(c, f.v), hy = dot(f.av, h);
  float ax = std::fabs(cx) - hx, ay = std::fabs(cy) - hy;  // distance of the x/y ranges from 0
  float x2 = ax > 0 ? ax * ax : 0, y2 = ay > 0 ? ay * ay : 0;
  return std::min(1.0f, mz / std::sqrt(x2 + y2 + mz * mz));
}

// Narrows a cosine lower bound by a cone of half-angle beta: cos(theta + beta), 0 past 90.
inline float coneNarrow(float cosTheta, float cosBeta, float sinBeta) {
  if (cosBeta <= 0 || cosTheta <= 0) return 0;
  float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
  return std::max(0.0f, cosTheta * cosBeta - sinTheta * sinBeta);
}

// Widens a cosine bound by a cone of half-angle beta: directions within beta of the axis
// can be up to beta closer to the target. cos(theta - beta) when theta > beta, else 1.
inline float coneWiden(float cosTheta, float cosBeta, float sinBeta) {
  if (cosBeta <= -1.0f || cosTheta >= cosBeta) return 1.0f;
  float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
  return std::min(1.0f, cosTheta * cosBeta + sinTheta * sinBeta);
}

// Frames of a shading point that every cluster bound reuses.
struct BoundFrames {
  Frame n, r;
  explicit BoundFrames(const ShadingPoint& sp) : n(makeFrame(sp.n)), r(makeFrame(sp.r)) {}
};

// A box of vectors seen in a frame: centre and half extent along each axis (the box
// rotated into the frame and re-bounded).
struct RotatedBox {
  float cx, hx, cy, hy, cz, hz;
  RotatedBox(const Frame& f, const Vec3& c, const Vec3& h)
      : cx(dot(c, f.u)), hx(dot(f.au, h)), cy(dot(c, f.v)), hy(dot(f.av, h)), cz(dot(c, f.w)), hz(dot(f.aw, h)) {}
  // Upper bound of the cosine to the frame's axis (as cosBoundBox).
  float cosUpper() const {
    float mz = cz + hz;
    if (mz <= 0) return 0;
    float ax = std::fabs(cx) - hx, ay = std::fabs(cy) - hy;
    float x2 = ax > 0 ? ax * ax : 0, y2 = ay > 0 ? ay * ay : 0;
    return std::min(1.0f, mz / std::sqrt(x2 + y2 + mz * mz));
  }
  // Lower bound of the cosine over the box's nearest z: z / sqrt(x^2 + y^2 + z^2) grows with z
  // and falls with x^2 + y^2, so it is least at z = cz - hz with |x|, |y| at their largest;
  // 0 when some vector may be at 90 degrees or more. Tighter than the smallest z over the
  // longest vector when the box is seen nearly head-on: a box of 1 straight above a point 3
  // away, 0.96 rather than 0.70 (clusterBounds takes the larger of the two).
  float cosLower() const {
    float minZ = cz - hz;
    if (minZ <= 0) return 0;
    float bx = std::fabs(cx) + hx, by = std::fabs(cy) + hy;
    return minZ / std::sqrt(bx * bx + by * by + minZ * minZ);
  }
};

// Bounds of the cosine between `target` and the unit vectors of a directional cluster,
// each with a little slack (see clusterBounds). The box holds unit vectors, whose cosine to
// the frame's axis is their z coordinate: within [cz - hz, cz + hz], and at most
// sqrt(1 - x^2 - y^2) (the box's general bounds divide by the vectors' lengths instead,
// looser for vectors known to be unit). And the node's cone (computeDirectionCones): the
// lights' travel directions lie within its half-angle of `axis`, so the directions toward
// them within it of -axis: the cosine is within cos(theta -+ beta), theta the angle from
// -axis to the target. A cone bounds a round patch of the sphere more tightly than its box
// once turned into the frame; each bound takes the better of the two.
struct CosRange {
  float up, lo;
};
inline CosRange unitCosBounds(const RotatedBox& b, const Vec3& target, const LightNode& node, float slack) {
  float ax = std::fabs(b.cx) - b.hx, ay = std::fabs(b.cy) - b.hy;
  float x2 = ax > 0 ? ax * ax : 0, y2 = ay > 0 ? ay * ay : 0;
  // 1 - x^2 - y^2 cancels near the horizon (z ~ 0): 2e-6 covers its float rounding.
  float up = std::min(b.cz + b.hz, std::sqrt(std::max(0.0f, 1 - x2 - y2) + 2e-6f));
  float lo = b.cz - b.hz;
  if (node.cosHalfAngle > -1) {
    const float cb = node.cosHalfAngle, sb = std::sqrt(std::max(0.0f, 1 - cb * cb));
    const float c = -dot(target, node.axis);
    up = std::min(up, coneWiden(c, cb, sb));
    lo = std::max(lo, coneNarrow(c, cb, sb));
  }
  return {up + slack, lo - slack};
}

// Upper bound (RGB) of the sum of the unshadowed contributions of the node's lights and,
// when `lower` is given, a lower bound: with visibility 1 the cluster gives something in
// [lower, upper], so upper - lower bounds the error of an unoccluded cluster's estimate.
// `smooth` (with `lower`) tells whether every light's contribution is a smooth function
// of its position and normal over the cluster: omni, oriented or directional lights (of
// their direction), every cosine
// bounded away from 0 (no clamp at the horizon) and no corner of the attenuation's clamp
// between the nearest and farthest light. Only then is the first-order estimate
// (estimate.h) valid.
// `low`: the group the lower bound uses when it differs (a tree that mixes groups passes
// their lower envelope, LightTree::boundLow); the contribution is then not called smooth.
// Cosine bounds get a little slack so float rounding in the exact evaluation can never
// exceed them (steep spot falloffs and high Phong exponents amplify it); and the final
// bounds a little more, so that float rounding never puts the upper bound below an exact
// value or the lower bound above it. (clusterBoundsPair, bounds_pair.h, uses the same.)
constexpr float kCosSlack = 2e-5f;
constexpr float kUpperScale = 1.0001f, kLowerScale = 0.9999f;

inline Color clusterBounds(const LightNode& node, LightType type, const LightGroup& g, const ShadingPoint& sp,
                           const BoundFrames& fr, Color* lower, bool* smooth = nullptr,
                           const LightGroup* low = nullptr) {
  const LightGroup& gl = low ? *low : g;
  if (lower) *lower = Color(0);
  if (smooth) *smooth = false;
  Vec3 lo, hi;  // vectors from the shading point toward the cluster's lights
  if (type == LightType::Directional) {
    lo = node.lo;
    hi = node.hi;
  } else {
    lo = node.lo - sp.p;
    hi = node.hi - sp.p;
  }
  Vec3 c = (lo + hi) * 0.5f, h = (hi - lo) * 0.5f;
  const bool directional = type == LightType::Directional;
  RotatedBox bn(fr.n, c, h);
  float cN = bn.cosUpper();
  if (cN <= 0) return Color(0);  // every light is behind the surface
  CosRange un{1, 0};
  if (directional) {
    un = unitCosBounds(bn, fr.n.w, node, kCosSlack);
    cN = std::min(cN, un.up);
    if (cN <= 0) return Color(0);
  }
  // Nearest and farthest vectors of the box: |q| lies in [dMin, dMax] for all of them.
  float dMax = length(vmax(vabs(lo), vabs(hi)));
  float dMin = std::sqrt(dot(vmax(vmax(lo, -hi), Vec3(0.0f)), vmax(vmax(lo, -hi), Vec3(0.0f))));
  // Lower cosine bounds: the smallest projection over the longest vector, or over the
  // longest the nearest projection can come with (RotatedBox::cosLower), the larger.
  // Lights that may be behind the surface give nothing at all, so no lower bound then
  // (specular neither).
  float cNLo = lower && dMax > 0 ? std::max(std::max(0.0f, (bn.cz - bn.hz) / dMax), bn.cosLower()) : 0.0f;
  if (lower && directional) cNLo = std::max(cNLo, un.lo);
  bool specular = !g.diffuseOnly && sp.hasSpecular();
  Color mUp = sp.kd * std::min(1.0f, cN + kCosSlack);
  Color mLo = sp.kd * cNLo;
  // Smooth: the first-order estimate applies (directional: its gradient is over the
  // directions, estimate.h).
  bool sm = lower && !low && cNLo > 0 &&
            (type == LightType::Omni || type == LightType::Oriented || directional);
  if (specular) {
    RotatedBox br(fr.r, c, h);
    float cRUp = br.cosUpper();
    CosRange ur{1, 0};
    if (directional && cRUp > 0) {
      ur = unitCosBounds(br, fr.r.w, node, kCosSlack);
      cRUp = std::max(0.0f, std::min(cRUp, ur.up));
    }
    mUp += sp.ks * powNonNegative(std::min(1.0f, cRUp + kCosSlack), sp.shininess);
    float cRLo = cNLo > 0 ? std::max(std::max(0.0f, (br.cz - br.hz) / dMax), br.cosLower()) : 0.0f;
    if (cNLo > 0 && directional) cRLo = std::max(cRLo, ur.lo);
    if (cNLo > 0) mLo += sp.ks * powNonNegative(cRLo, sp.shininess);
    sm = sm && cRLo > 0;
  }
  float gUp = 1, gLo = 1;
  if (type != LightType::Directional) {
    gUp = g.atten(dMin);
    if (lower) gLo = gl.atten(dMax);
    sm = sm && gLo > 0 && !g.atten.kinkBetween(dMin, dMax);
    if (type == LightType::Oriented || type == LightType::Spot) {
      // The light's cosine is between its axis a and the direction from a light to the
      // point, which lies in the box -[lo, hi]: projection onto a over the length, bounded
      // by the projection's range and [dMin, dMax]; then widened/narrowed by the cone.
      float pc = -dot(c, node.axis), ph = dot(vabs(node.axis), h);
      float up = pc + ph;
      // A negative projection is a cosine below 0 for every light, at most up / dMax (the
      // longest vector brings it nearest 0). It is kept, not clamped to 0: widened by the
      // cone it stays below 0 when every light faces away from the point (the far side of
      // a luminous sphere), where 0 would widen to sin(beta) and keep those lights.
      float cosUp = up <= 0 ? (dMax > 0 ? std::max(-1.0f, up / dMax) : 0.0f)
                            : (dMin > 0 ? std::min(1.0f, up / dMin) : 1.0f);
      // The slack only rounds a positive bound up: a zero bound is exact (nothing reaches).
      // One square root per bound: cheaper than the node's bytes it would take to store.
      const float sinHalfAngle = std::sqrt(std::max(0.0f, 1 - node.cosHalfAngle * node.cosHalfAngle));
      float cUp = std::max(0.0f, coneWiden(cosUp, node.cosHalfAngle, sinHalfAngle));
      if (cUp > 0) cUp = std::min(1.0f, cUp + kCosSlack);
      gUp *= type == LightType::Oriented ? cUp : g.falloff(cUp);
      if (lower) {
        // 0 means "may be 90 degrees or more", not a cosine: no lower bound then.
        float cLo = dMax > 0 ? coneNarrow(std::max(0.0f, (pc - ph) / dMax), node.cosHalfAngle, sinHalfAngle) : 0.0f;
        gLo *= cLo <= 0 ? 0.0f : (type == LightType::Oriented ? cLo : gl.falloff(cLo));
        sm = sm && cLo > 0;
      }
    }
  }
  if (lower) *lower = mLo * (gLo * kLowerScale) * node.intensity;
  if (smooth) *smooth = sm;
  return mUp * (gUp * kUpperScale) * node.intensity;
}

inline Color clusterBound(const LightNode& node, LightType type, const LightGroup& g, const ShadingPoint& sp,
                          const BoundFrames& fr) {
  return clusterBounds(node, type, g, sp, fr, nullptr);
}

inline Color clusterLowerBound(const LightNode& node, LightType type, const LightGroup& g,
                               const ShadingPoint& sp, const BoundFrames& fr) {
  Color lower;
  clusterBounds(node, type, g, sp, fr, &lower);
  return lower;
}

}  // namespace lc::lightcuts
