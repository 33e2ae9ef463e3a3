#include "lightcuts/estimate.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "lightcuts/bounds.h"
#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::Config;
using test_lights::randomConfig;
using test_lights::randomUnit;

Color unshadowed(const Light& l, const LightGroup& g, const ShadingPoint& sp) {
  Color mg(0);
  Vec3 wi;
  float d;
  lightContribution(l, g, sp, mg, wi, d);
  return mg;
}

// The luminance-weighted mean position and normal of a set of lights (what NodeMoments
// holds for a cluster).
NodeMoments momentsOf(const LightSet& s) {
  NodeMoments m;
  float w = 0;
  for (const Light& l : s.lights) {
    float li = luminance(l.intensity);
    m.centroid += l.position * li;
    m.meanAxis += l.direction * li;
    w += li;
  }
  m.centroid /= w;
  m.meanAxis /= w;
  return m;
}

// Moving the cluster's mean by e from the representative: the representative's own value
// is off by O(e), the first-order estimate by O(e^2) (a quarter when e halves).
TEST(FirstOrderUnit, ErrorIsOfSecondOrder) {
  Rng r(5, 5);
  int tested = 0;
  for (int i = 0; i < 2000; ++i) {
    LightType type = r.below(2) ? LightType::Oriented : LightType::Omni;
    LightGroup g = test_lights::randomGroup(r, type);
    g.atten.maxDistance = kInf;
    ShadingPoint sp = test_lights::point(Vec3(0, 0, 0));
    sp.n = randomUnit(r);
    sp.r = randomUnit(r);
    if (r.below(2)) sp.ks = Color(0);
    Light l;
    l.type = type;
    l.position = randomUnit(r) * (1 + 3 * r.uniform());
    l.direction = randomUnit(r);
    l.intensity = Color(1);
    Color f0 = unshadowed(l, g, sp);
    if (luminance(f0) < 1e-3f) continue;
    Vec3 dx = randomUnit(r), dn = randomUnit(r);
    double err[2], repErr[2];
    bool ok = true;
    for (int k = 0; k < 2; ++k) {
      float e = k == 0 ? 0.02f : 0.01f;
      NodeMoments m{l.position - dx * e, l.direction - dn * e};
      Light mean = l;
      mean.position = m.centroid;
      mean.direction = m.meanAxis;
      Color fm = unshadowed(mean, g, sp);
      // The segment from the mean to the representative must stay clear of every clamp.
      ok = ok && luminance(fm) > 0.5f * luminance(f0) && g.atten.derivative(length(l.position)) != 0 &&
           g.atten.derivative(length(m.centroid)) != 0;
      err[k] = std::fabs(luminance(firstOrderUnit(l, g, sp, m, f0)) - luminance(fm));
      repErr[k] = std::fabs(luminance(f0) - luminance(fm));
    }
    // Only where the first-order term dominates the representative's error (it halves
    // with e), not where dx happens to be nearly orthogonal to the gradient.
    if (!ok || repErr[1] < 1e-4 * luminance(f0) || std::fabs(repErr[1] / repErr[0] - 0.5) > 0.05) continue;
    ++tested;
    EXPECT_LT(err[1], 0.2 * repErr[1]) << "config " << i;
    EXPECT_LT(err[1], 0.4 * err[0] + 1e-6 * luminance(f0)) << "config " << i;
  }
  EXPECT_GT(tested, 300);
}

TEST(FirstOrderUnit, LightAtItsOwnMeanIsUnchanged) {
  Light l;
  l.type = LightType::Oriented;
  l.position = Vec3(0.5f, 2, 0.3f);
  l.direction = normalize(Vec3(-0.2f, -1, 0.1f));
  LightGroup g;
  ShadingPoint sp = test_lights::point(Vec3(0, 0, 0));
  Color f = unshadowed(l, g, sp);
  Color fo = firstOrderUnit(l, g, sp, NodeMoments{l.position, l.direction}, f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fo[c], f[c], 1e-6f * f[c]);
}

// Over random smooth clusters, with each light in turn as the representative: the
// first-order estimate is far closer to the cluster's true sum than the representative's.
TEST(FirstOrderUnit, ClusterEstimatesAreCloserThanTheRepresentatives) {
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    Rng r(11, uint64_t(type));
    double foErr = 0, repErr = 0;
    int clusters = 0;
    for (int i = 0; i < 20000 && clusters < 400; ++i) {
      Config c = randomConfig(r, type);
      if (c.set.lights.size() < 4) continue;
      BoundFrames fr(c.sp);
      Color lower;
      bool smooth = false;
      clusterBounds(c.node, type, c.set.groups[0], c.sp, fr, &lower, &smooth);
      if (!smooth) continue;
      ++clusters;
      const LightGroup& g = c.set.groups[0];
      NodeMoments m = momentsOf(c.set);
      double truth = luminance(test_lights::trueSum(c));
      for (const Light& rep : c.set.lights) {
        Color f = unshadowed(rep, g, c.sp);
        double w = luminance(rep.intensity) / luminance(c.node.intensity);
        repErr += w * std::fabs(luminance(f * c.node.intensity) - truth) / truth;
        foErr += w * std::fabs(luminance(firstOrderUnit(rep, g, c.sp, m, f) * c.node.intensity) - truth) / truth;
      }
    }
    ASSERT_GT(clusters, 100) << lightTypeName(type);
    EXPECT_LT(foErr, 0.3 * repErr) << lightTypeName(type);
  }
}

TEST(Estimator, ParsesNames) {
  EXPECT_EQ(parseEstimator("first-order"), Estimator::FirstOrder);
  EXPECT_EQ(parseEstimator("representative"), Estimator::Representative);
  EXPECT_STREQ(estimatorName(Estimator::FirstOrder), "first-order");
  EXPECT_THROW(parseEstimator("centroid"), Error);
}

}  // namespace
}  // namespace lc::lightcuts
