// The bounds of two clusters at once: the two children of a node being refined, which a
// cut bounds one right after the other (issue 21: "SIMD bounds, both children of a node at
// once"). Each child is one lane of SSE registers, and every lane goes through the very
// operations clusterBounds (bounds.h) does, in the same order and without fused
// multiply-adds, so the results are the same bit for bit (bounds_pair_test.cpp checks it on
// random clusters). Only the specular power and the spot falloff stay scalar, per lane.
// For omni, oriented and spot trees that do not mix groups (boundsPairApplies); directional
// trees and mixed ones go through clusterBounds one child at a time.
#pragma once

#include <cstring>

#include "lightcuts/bounds.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lc::lightcuts {

// What clusterBounds gives a child when asked for its lower bound too.
struct ChildBounds {
  Color upper, lower;
  bool smooth = false;
};

inline bool boundsPairApplies(LightType type, bool mixedGroups) {
  return !mixedGroups && (type == LightType::Omni || type == LightType::Oriented || type == LightType::Spot);
}

#if defined(__SSE2__)
namespace detail {

// Lanes 0 and 1 hold the two children (2 and 3 repeat the second).
struct Lanes3 {
  __m128 x, y, z;
};
inline __m128 pairOf(float a, float b) { return _mm_setr_ps(a, b, b, b); }
inline Lanes3 pairOf(const Vec3& a, const Vec3& b) { return {pairOf(a.x, b.x), pairOf(a.y, b.y), pairOf(a.z, b.z)}; }
inline Lanes3 splat(const Vec3& v) { return {_mm_set1_ps(v.x), _mm_set1_ps(v.y), _mm_set1_ps(v.z)}; }
inline Lanes3 operator+(const Lanes3& a, const Lanes3& b) {
  return {_mm_add_ps(a.x, b.x), _mm_add_ps(a.y, b.y), _mm_add_ps(a.z, b.z)};
}
inline Lanes3 operator-(const Lanes3& a, const Lanes3& b) {
  return {_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)};
}
inline Lanes3 operator*(const Lanes3& a, __m128 s) { return {_mm_mul_ps(a.x, s), _mm_mul_ps(a.y, s), _mm_mul_ps(a.z, s)}; }
// a.x * b.x + a.y * b.y + a.z * b.z, added left to right as dot() does.
inline __m128 dot(const Lanes3& a, const Lanes3& b) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}
inline __m128 absLanes(__m128 v) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), v); }
inline Lanes3 absLanes(const Lanes3& v) { return {absLanes(v.x), absLanes(v.y), absLanes(v.z)}; }
inline __m128 negLanes(__m128 v) { return _mm_xor_ps(_mm_set1_ps(-0.0f), v); }
// std::min(a, b) is (b < a) ? b : a, and _mm_min_ps(x, y) is (x < y) ? x : y; likewise max.
inline __m128 minStd(__m128 a, __m128 b) { return _mm_min_ps(b, a); }
inline __m128 maxStd(__m128 a, __m128 b) { return _mm_max_ps(b, a); }
inline Lanes3 maxStd(const Lanes3& a, const Lanes3& b) { return {maxStd(a.x, b.x), maxStd(a.y, b.y), maxStd(a.z, b.z)}; }
// mask ? a : b, lane by lane.
inline __m128 select(__m128 mask, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }

// A frame's axes in every lane.
struct FrameLanes {
  Lanes3 u, v, w, au, av, aw;
  explicit FrameLanes(const Frame& f)
      : u(splat(f.u)), v(splat(f.v)), w(splat(f.w)), au(splat(f.au)), av(splat(f.av)), aw(splat(f.aw)) {}
};

// RotatedBox(f, c, h).cosUpper(), its cz - hz (the lower bounds' numerator) and its
// cosLower() (0 where cz - hz <= 0).
inline __m128 cosUpperLanes(const FrameLanes& f, const Lanes3& c, const Lanes3& h, __m128& minZ, __m128& lowerCos) {
  const __m128 zero = _mm_setzero_ps();
  const __m128 cx = dot(c, f.u), hx = dot(f.au, h);
  const __m128 cy = dot(c, f.v), hy = dot(f.av, h);
  const __m128 cz = dot(c, f.w), hz = dot(f.aw, h);
  minZ = _mm_sub_ps(cz, hz);
  {
    const __m128 bx = _mm_add_ps(absLanes(cx), hx), by = _mm_add_ps(absLanes(cy), hy);
    const __m128 s = _mm_add_ps(_mm_add_ps(_mm_mul_ps(bx, bx), _mm_mul_ps(by, by)), _mm_mul_ps(minZ, minZ));
    lowerCos = _mm_and_ps(_mm_cmpgt_ps(minZ, zero), _mm_div_ps(minZ, _mm_sqrt_ps(s)));
  }
  const __m128 mz = _mm_add_ps(cz, hz);
  const __m128 ax = _mm_sub_ps(absLanes(cx), hx), ay = _mm_sub_ps(absLanes(cy), hy);
  const __m128 x2 = _mm_and_ps(_mm_cmpgt_ps(ax, zero), _mm_mul_ps(ax, ax));
  const __m128 y2 = _mm_and_ps(_mm_cmpgt_ps(ay, zero), _mm_mul_ps(ay, ay));
  const __m128 q = _mm_div_ps(mz, _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(x2, y2), _mm_mul_ps(mz, mz))));
  return _mm_andnot_ps(_mm_cmple_ps(mz, zero), minStd(_mm_set1_ps(1.0f), q));
}

// g(d) lane by lane, as Attenuation::operator(); `den` is its denominator (kinkBetween's).
inline __m128 attenLanes(const Attenuation& a, __m128 d, __m128& den) {
  den = _mm_add_ps(_mm_set1_ps(a.constant),
                   _mm_mul_ps(d, _mm_add_ps(_mm_set1_ps(a.linear), _mm_mul_ps(d, _mm_set1_ps(a.quadratic)))));
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 v = select(_mm_cmple_ps(den, one), one, _mm_div_ps(one, den));
  return _mm_andnot_ps(_mm_cmpgt_ps(d, _mm_set1_ps(a.maxDistance)), v);
}

}  // namespace detail
#endif

// What clusterBoundsPair needs of a shading point, its frames' axes and position set in
// every lane once per cut rather than once per pair (the broadcasts were a tenth of its
// instructions, callgrind).
struct PairFrames {
  const ShadingPoint& sp;
  const BoundFrames& fr;
#if defined(__SSE2__)
  detail::FrameLanes n, r;
  detail::Lanes3 p;
  PairFrames(const ShadingPoint& s, const BoundFrames& f)
      : sp(s), fr(f), n(f.n), r(f.r), p(detail::splat(s.p)) {}
#else
  PairFrames(const ShadingPoint& s, const BoundFrames& f) : sp(s), fr(f) {}
#endif
};

// clusterBounds(a, ...) and clusterBounds(b, ...), each with its lower bound and smoothness.
inline void clusterBoundsPair(const LightNode& a, const LightNode& b, LightType type, const LightGroup& g,
                              const PairFrames& pf, ChildBounds out[2]) {
  const ShadingPoint& sp = pf.sp;
#if defined(__SSE2__)
  using namespace detail;
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), slack = _mm_set1_ps(kCosSlack);
  const Lanes3& p = pf.p;
  const Lanes3 lo = pairOf(a.lo, b.lo) - p, hi = pairOf(a.hi, b.hi) - p;
  const __m128 half = _mm_set1_ps(0.5f);
  const Lanes3 c = (lo + hi) * half, h = (hi - lo) * half;
  __m128 nMinZ, nLowerCos;
  const __m128 cN = cosUpperLanes(pf.n, c, h, nMinZ, nLowerCos);
  const __m128 behind = _mm_cmple_ps(cN, zero);  // every light behind the surface: 0
  const Lanes3 far = maxStd(absLanes(lo), absLanes(hi));
  const __m128 dMax = _mm_sqrt_ps(dot(far, far));
  const Lanes3 near = maxStd(maxStd(lo, Lanes3{negLanes(hi.x), negLanes(hi.y), negLanes(hi.z)}),
                             Lanes3{zero, zero, zero});
  const __m128 dMin = _mm_sqrt_ps(dot(near, near));
  const __m128 dMaxPositive = _mm_cmpgt_ps(dMax, zero);
  const __m128 cNLo = _mm_and_ps(dMaxPositive, maxStd(maxStd(zero, _mm_div_ps(nMinZ, dMax)), nLowerCos));
  const __m128 mUpScale = minStd(one, _mm_add_ps(cN, slack));
  // A spot's falloff is not smooth for the first-order estimate (clusterBounds).
  __m128 smooth = type == LightType::Spot ? zero : _mm_cmpgt_ps(cNLo, zero);
  const bool specular = !g.diffuseOnly && sp.hasSpecular();
  __m128 cRUpSlack = zero, cRLo = zero;
  if (specular) {
    __m128 rMinZ, rLowerCos;
    const __m128 cRUp = cosUpperLanes(pf.r, c, h, rMinZ, rLowerCos);
    cRUpSlack = minStd(one, _mm_add_ps(cRUp, slack));
    cRLo = _mm_and_ps(_mm_cmpgt_ps(cNLo, zero), maxStd(maxStd(zero, _mm_div_ps(rMinZ, dMax)), rLowerCos));
    smooth = _mm_and_ps(smooth, _mm_cmpgt_ps(cRLo, zero));
  }
  __m128 denMin, denMax;
  __m128 gUp = attenLanes(g.atten, dMin, denMin);
  __m128 gLo = attenLanes(g.atten, dMax, denMax);
  smooth = _mm_and_ps(smooth, _mm_cmpgt_ps(gLo, zero));
  smooth = _mm_andnot_ps(_mm_and_ps(_mm_cmple_ps(denMin, one), _mm_cmpgt_ps(denMax, one)), smooth);
  // Spots: the cosines to their axes, through the falloff per lane below.
  __m128 spotUp = zero, spotLo = zero;
  const bool spot = type == LightType::Spot;
  if (type == LightType::Oriented || spot) {
    const Lanes3 axis = pairOf(a.axis, b.axis);
    const __m128 pc = negLanes(dot(c, axis)), ph = dot(absLanes(axis), h);
    const __m128 up = _mm_add_ps(pc, ph);
    const __m128 cosUpFacing = select(_mm_cmpgt_ps(dMin, zero), minStd(one, _mm_div_ps(up, dMin)), one);
    const __m128 cosUpAway = _mm_and_ps(dMaxPositive, maxStd(_mm_set1_ps(-1.0f), _mm_div_ps(up, dMax)));
    const __m128 cosUp = select(_mm_cmple_ps(up, zero), cosUpAway, cosUpFacing);
    const __m128 cb = pairOf(a.cosHalfAngle, b.cosHalfAngle);
    const __m128 sb = _mm_sqrt_ps(maxStd(zero, _mm_sub_ps(one, _mm_mul_ps(cb, cb))));
    // coneWiden(cosUp, cb, sb)
    const __m128 sUp = _mm_sqrt_ps(maxStd(zero, _mm_sub_ps(one, _mm_mul_ps(cosUp, cosUp))));
    const __m128 widened = minStd(one, _mm_add_ps(_mm_mul_ps(cosUp, cb), _mm_mul_ps(sUp, sb)));
    const __m128 whole = _mm_or_ps(_mm_cmple_ps(cb, _mm_set1_ps(-1.0f)), _mm_cmpge_ps(cosUp, cb));
    __m128 cUp = maxStd(zero, select(whole, one, widened));
    cUp = select(_mm_cmpgt_ps(cUp, zero), minStd(one, _mm_add_ps(cUp, slack)), cUp);
    if (spot)
      spotUp = cUp;
    else
      gUp = _mm_mul_ps(gUp, cUp);
    // coneNarrow(max(0, (pc - ph) / dMax), cb, sb) where dMax > 0, else 0
    const __m128 t = maxStd(zero, _mm_div_ps(_mm_sub_ps(pc, ph), dMax));
    const __m128 sT = _mm_sqrt_ps(maxStd(zero, _mm_sub_ps(one, _mm_mul_ps(t, t))));
    const __m128 narrowed = maxStd(zero, _mm_sub_ps(_mm_mul_ps(t, cb), _mm_mul_ps(sT, sb)));
    const __m128 none = _mm_or_ps(_mm_cmple_ps(cb, zero), _mm_cmple_ps(t, zero));
    const __m128 cLo = _mm_and_ps(dMaxPositive, _mm_andnot_ps(none, narrowed));
    const __m128 cLoPositive = _mm_cmpgt_ps(cLo, zero);
    if (spot)
      spotLo = cLo;
    else
      gLo = _mm_and_ps(cLoPositive, _mm_mul_ps(gLo, cLo));
    smooth = _mm_and_ps(smooth, cLoPositive);
  }
  alignas(16) float vUp[4], vLo[4], vCR[4], vCRLo[4], vGUp[4], vGLo[4], vSm[4], vBehind[4], vSpotUp[4],
      vSpotLo[4];
  _mm_store_ps(vSpotUp, spotUp);
  _mm_store_ps(vSpotLo, spotLo);
  _mm_store_ps(vUp, mUpScale);
  _mm_store_ps(vLo, cNLo);
  _mm_store_ps(vCR, cRUpSlack);
  _mm_store_ps(vCRLo, cRLo);
  _mm_store_ps(vGUp, gUp);
  _mm_store_ps(vGLo, gLo);
  _mm_store_ps(vSm, smooth);
  _mm_store_ps(vBehind, behind);
  for (int k = 0; k < 2; ++k) {
    const LightNode& n = k ? b : a;
    ChildBounds& o = out[k];
    uint32_t behindBits;
    std::memcpy(&behindBits, &vBehind[k], sizeof behindBits);
    if (behindBits != 0) {
      o = ChildBounds{};
      continue;
    }
    Color mUp = sp.kd * vUp[k];
    Color mLo = sp.kd * vLo[k];
    if (specular) {
      mUp += sp.ks * powNonNegative(vCR[k], sp.shininess);
      if (vLo[k] > 0) mLo += sp.ks * powNonNegative(vCRLo[k], sp.shininess);
    }
    if (spot) {
      vGUp[k] *= g.falloff(vSpotUp[k]);
      vGLo[k] *= vSpotLo[k] <= 0 ? 0.0f : g.falloff(vSpotLo[k]);
    }
    uint32_t smoothBits;
    std::memcpy(&smoothBits, &vSm[k], sizeof smoothBits);
    o.lower = mLo * (vGLo[k] * kLowerScale) * n.intensity;
    o.smooth = smoothBits != 0;
    o.upper = mUp * (vGUp[k] * kUpperScale) * n.intensity;
  }
#else
  for (int k = 0; k < 2; ++k)
    out[k].upper = clusterBounds(k ? b : a, type, g, sp, pf.fr, &out[k].lower, &out[k].smooth);
#endif
}

inline void clusterBoundsPair(const LightNode& a, const LightNode& b, LightType type, const LightGroup& g,
                              const ShadingPoint& sp, const BoundFrames& fr, ChildBounds out[2]) {
  clusterBoundsPair(a, b, type, g, PairFrames(sp, fr), out);
}

}  // namespace lc::lightcuts
