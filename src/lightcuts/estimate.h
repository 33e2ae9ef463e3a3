// The first-order estimate of a cluster (an extension of Walter et al. 2005; --estimator
// first-order, the default; `representative` is the published estimate).
//
// Lightcuts estimates a cluster by its representative j: I_C * f(x_j, n_j), f the
// unshadowed contribution per unit intensity of a light at x with normal n. Its error is
// first order in the cluster's size: f(x_j) - mean f ~ grad f . (x_j - mean x). The mean
// position and normal of the cluster's lights, weighted by intensity, are known
// (NodeMoments), so that term can be subtracted, as a control variate:
//   estimate = I_C * (f(x_j, n_j) - grad f(mu, n_mean) . (x_j - mu, n_j - n_mean))
// which leaves an error of second order (the curvature of 1/d^2 and of the cosines over the
// cluster), with no bias: averaged over the representative's choice it is the cluster's
// mean to second order. It is valid only where f is smooth over the whole cluster: no
// cosine may be clamped at a horizon and no attenuation clamp's corner may lie within it
// (clusterBounds' `smooth`); elsewhere, and for leaves, the representative's estimate is
// used. Visibility stays the representative's: a partly hidden cluster keeps its error.
// Measured (docs/LIGHTCUTS.md): on the Cornell box's unoccluded clusters the error is a
// fifth of the representative's.
#pragma once

#include <cmath>
#include <string>
#include <string_view>

#include "core/enum_names.h"
#include "core/math.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/shading.h"

namespace lc::lightcuts {

enum class Estimator { Representative, FirstOrder };
// Its names (core/enum_names.h), read by the functions below and by render --estimator.
inline constexpr EnumName<Estimator> kEstimatorNames[] = {
    {Estimator::FirstOrder, "first-order",
     "its representative's, less the first-order change from the cluster's mean light, where smooth"},
    {Estimator::Representative, "representative", "as published"}};
// Throws lc::Error for another name.
inline Estimator parseEstimator(std::string_view name) { return parseEnum(kEstimatorNames, name, "estimator"); }
inline const char* estimatorName(Estimator e) { return enumName(kEstimatorNames, e); }

// f(rep) minus the first-order change of f from the cluster's mean light (position mu,
// normal n_mean) to the representative, with the gradient taken at the mean:
//   f(x_j) - grad f(mu) . (x_j - mu) = f(mu) + (1/2) d^T H d + ...,  d = x_j - mu,
// whose expectation over the representative's choice (probability proportional to
// intensity) is the cluster's mean of f to second order: no bias is added. (The gradient
// at x_j instead would leave -(1/2) d^T H d, the same sign for every cluster: errors that
// add up over a cut instead of cancelling.) Per unit intensity and unshadowed, omni,
// oriented and directional lights; `unit` is lightContribution()'s value for `rep` (M * G).
//
// Directional lights (environments): f is a function of the unit direction w toward the
// light, extended to all vectors as f(w) = kd N.w + ks (R.w)^s, and the cluster's mean
// direction m (NodeMoments::centroid, |m| <= 1) is where its gradient is taken:
//   f(w_j) - grad f(m) . (w_j - m).
// The diffuse term is linear in w, so for it this is kd N.m, the cluster's exact mean
// (in luminance: the moments are luminance-weighted), whichever light represents it; the
// specular term keeps a second-order error (and none at shininess 1).
inline Color firstOrderUnit(const Light& rep, const LightGroup& g, const ShadingPoint& sp, const NodeMoments& m,
                            const Color& unit) {
  if (isBlack(unit)) return unit;
  if (rep.type == LightType::Directional) {
    Vec3 dw = -rep.direction - m.centroid;  // the representative's direction less the mean
    Color dMat = sp.kd * dot(sp.n, dw);
    if (!g.diffuseOnly && sp.hasSpecular() && sp.shininess > 0) {
      float cR = dot(sp.r, m.centroid);
      if (cR > 0) dMat += sp.ks * (sp.shininess * powNonNegative(cR, sp.shininess - 1) * dot(sp.r, dw));
    }
    return unit - dMat;
  }
  Vec3 d = m.centroid - sp.p;
  float r = length(d);
  if (!(r > 0)) return unit;
  float invR = 1 / r;
  Vec3 w = d * invR;
  Vec3 dx = rep.position - m.centroid;  // how far the representative is from the mean
  float wdx = dot(w, dx);
  // Directional derivatives along dx of each factor: d(N.w) = (N.dx - (N.w)(w.dx)) / r.
  float cN = dot(sp.n, w);
  float dN = (dot(sp.n, dx) - cN * wdx) * invR;
  float A = g.atten(r);
  float dA = g.atten.derivative(r) * wdx;
  float cL = 1, dL = 0;
  if (rep.type == LightType::Oriented) {
    // cos at the light: -n.w, linear in n; along dx it changes by -(n.dx + cL (w.dx)) / r,
    // and from n_mean to the representative's normal by -w.(n_j - n_mean).
    cL = -dot(m.meanAxis, w);
    dL = -(dot(m.meanAxis, dx) + cL * wdx) * invR - dot(w, rep.direction - m.meanAxis);
  }
  Color mat = sp.kd * cN, dMat = sp.kd * dN;
  if (!g.diffuseOnly && sp.hasSpecular()) {
    float cR = std::max(0.0f, dot(sp.r, w));
    float dR = (dot(sp.r, dx) - cR * wdx) * invR;
    // Shininess 0: a constant factor 1 (as lightContribution() has it), no derivative.
    float p1 = sp.shininess > 0 && cR > 0 ? powNonNegative(cR, sp.shininess - 1) : 0.0f;
    mat += sp.ks * (sp.shininess > 0 ? p1 * cR : 1.0f);
    dMat += sp.ks * (sp.shininess * p1 * dR);
  }
  float geo = cL * A, dGeo = dL * A + cL * dA;
  return unit - (dMat * geo + mat * dGeo);
}

}  // namespace lc::lightcuts
