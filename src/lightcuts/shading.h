// The receiving side of a light evaluation, and the exact contribution of one light.
// Brute force, the Lightcuts estimate and the seed's cuts all call lightContribution(), so
// the three methods agree exactly wherever a cut reaches single lights.
#pragma once

#include <cmath>

#include "core/math.h"
#include "core/light.h"

namespace lc::lightcuts {

// Everything the course's Phong model needs at a shading point:
//   M = kd*max(N.L,0) + ks*max(R.L,0)^shininess   (no light from behind: N.L <= 0 gives 0)
// with R the mirror of the view direction about N (so R.L equals the course's R_L.V).
struct ShadingPoint {
  Vec3 p;          // position
  Vec3 n;          // unit shading normal, facing the viewer
  Vec3 r;          // unit mirror direction of the view vector about n
  Color kd, ks;
  float shininess = 0;
  // Luminance below which the relative error criterion counts absolute error (the cut
  // stops when its bounds are within error x max(estimate, errorFloor)): the renderer's
  // --error-floor, divided by the weight this point's light has in its pixel. 0 = none.
  float errorFloor = 0;
  // The relative error this point's cut is held to is at least this (the evaluator's
  // --error otherwise): the error floor's pre-pass (render/renderer.cpp), which needs only
  // the image's mean luminance, asks for less. 0 = the evaluator's alone.
  float minError = 0;
  // Whether the cut may test clusters for being clear (CutOptions::clearClusters): the
  // renderer turns the tests off where its pre-pass found they rarely pass (clearTestsPay).
  bool clearTests = true;

  bool hasSpecular() const { return !isBlack(ks); }
  bool isBlackBody() const { return isBlack(kd) && isBlack(ks); }
};

// Visibility from the shading point toward a light: 1 when unoccluded, 0 when blocked,
// the transmissive colour product through glass. Implemented by the renderer.
class Visibility {
 public:
  virtual ~Visibility() = default;
  // wi: unit direction to the light; dist: distance to it (infinity for directional).
  virtual Color operator()(const Vec3& wi, float dist) = 0;
  // As operator(), and what stopped the ray: `blocker` is kVisible when nothing opaque
  // did, the index of a convex opaque object that did (the renderer numbers convex shapes,
  // then the flat convex faces of meshes), with the distance to it in `tHit`, or
  // kUnknownBlocker (a non-convex or unknown occluder). A convex object that
  // blocks a set of directions blocks their convex hull too, which is what the visibility
  // probes (evaluator.h) build on.
  static constexpr int kVisible = -1;
  static constexpr int kUnknownBlocker = -2;
  virtual Color trace(const Vec3& wi, float dist, int& blocker, float& tHit) {
    Color v = (*this)(wi, dist);
    blocker = isBlack(v) ? kUnknownBlocker : kVisible;
    tHit = 0;
    return v;
  }
  // Whether every shadow ray toward a point of the box [lo, hi] (a cluster's light
  // positions) is certainly unblocked, without tracing any: a conservative test, false
  // when it cannot tell (and by default). `hint` is the implementation's to keep between
  // calls (what stopped an earlier test, tried first); kNoHint to begin with.
  static constexpr uint32_t kNoHint = ~0u;
  virtual bool boxClear(const Vec3& lo, const Vec3& hi, uint32_t& hint) { return false; }
  // A box that every shadow ray from this point which trace() finds stopped by convex
  // object `blocker` passes through within its first `dist` (the object's bounds, padded
  // for the ray's offset from the point): a ray toward wi that misses it cannot be
  // stopped by that object there. False when not known (and by default).
  virtual bool blockerBox(int blocker, Vec3& lo, Vec3& hi) const { return false; }
  // Whether convex object `blocker` certainly stops every shadow ray from this point toward
  // the unit directions dirs[0, n) nearer than tMax, decided without rays (each segment
  // passes through its inside, deeper than the rays' offsets from it): 1 yes, 0 not proven,
  // -1 cannot tell (the caller traces rays). -1 by default.
  virtual int blocksAll(int blocker, const Vec3* dirs, int n, float tMax) const { return -1; }
};

// M * G of one light per unit intensity, without visibility. Returns false when the
// contribution is exactly zero (then no shadow ray is needed).
inline bool lightContribution(const Light& l, const LightGroup& g, const ShadingPoint& sp,
                              Color& mg, Vec3& wi, float& dist) {
  float G;
  if (l.type == LightType::Directional) {
    wi = -l.direction;
    dist = kInf;
    G = 1;
  } else {
    Vec3 d = l.position - sp.p;
    float d2 = length2(d);
    if (!(d2 > 0)) return false;
    dist = std::sqrt(d2);
    wi = d / dist;
    G = g.atten(dist);
    if (l.type == LightType::Oriented)
      G *= std::max(0.0f, -dot(l.direction, wi));
    else if (l.type == LightType::Spot)
      G *= g.falloff(-dot(l.direction, wi));
  }
  if (!(G > 0)) return false;
  float cosN = dot(sp.n, wi);
  if (!(cosN > 0)) return false;
  Color m = sp.kd * cosN;
  if (!g.diffuseOnly && sp.hasSpecular()) {
    float cosR = std::max(0.0f, dot(sp.r, wi));
    if (cosR > 0 || sp.shininess == 0) m += sp.ks * powNonNegative(cosR, sp.shininess);
  }
  mg = m * G;
  return !isBlack(mg);
}

}  // namespace lc::lightcuts
