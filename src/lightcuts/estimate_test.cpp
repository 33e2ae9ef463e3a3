#include "lightcuts/estimate.h"

#include <gtest/gtest.h>

#include <vector>

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

// Directional lights (an environment's): for a diffuse surface and a cluster wholly above
// its horizon, the first-order estimate is the cluster's exact sum (in luminance) whichever
// light represents it, where the representative alone is off by tens of percent; with a
// Phong lobe it still beats the representative on the whole.
TEST(FirstOrderUnit, DirectionalClusterAboveTheHorizonIsExactForDiffuse) {
  Rng r(24, 1);
  LightGroup g;
  g.atten = Attenuation{0, 0, 0, kInf};
  int tested = 0;
  double specRep = 0, specFo = 0;  // summed over the specular configurations
  for (int i = 0; i < 300; ++i) {
    ShadingPoint sp = test_lights::point(Vec3(0, 0, 0));
    sp.n = randomUnit(r);
    sp.r = normalize(reflect(randomUnit(r), sp.n));
    const bool specular = i % 2 == 1;
    sp.kd = Color(0.5f);
    sp.ks = specular ? Color(0.3f) : Color(0);
    sp.shininess = 8;
    const Vec3 axis = randomUnit(r);
    std::vector<Light> ls(16);
    NodeMoments m;
    double wsum = 0, truth = 0;
    bool above = true;
    for (Light& l : ls) {
      l.type = LightType::Directional;
      l.direction = -test_lights::randomInCone(r, axis, 0.4f);
      l.intensity = Color(0.5f + r.uniform(), 0.5f + r.uniform(), 0.5f + r.uniform());
      float w = luminance(l.intensity);
      m.centroid += -l.direction * w;
      wsum += w;
      above = above && dot(sp.n, -l.direction) > 0 && (!specular || dot(sp.r, -l.direction) > 0);
      truth += luminance(unshadowed(l, g, sp) * l.intensity);
    }
    if (!above) continue;
    m.centroid /= float(wsum);
    ++tested;
    double repErr = 0, foErr = 0;
    for (const Light& rep : ls) {
      Color f = unshadowed(rep, g, sp);
      double w = luminance(rep.intensity) / wsum;
      repErr += w * std::fabs(luminance(f) * wsum - truth) / truth;
      double fo = luminance(firstOrderUnit(rep, g, sp, m, f)) * wsum;
      foErr += w * std::fabs(fo - truth) / truth;
      if (!specular) {
        EXPECT_NEAR(fo, truth, 1e-4 * truth) << "config " << i;
      }
    }
    if (specular) {
      specRep += repErr;
      specFo += foErr;
    } else {
      EXPECT_LT(foErr, 0.01 * repErr) << "config " << i;
    }
  }
  EXPECT_GT(tested, 60);
  EXPECT_LT(specFo, 0.5 * specRep);
  RecordProperty("specular_error_ratio", std::to_string(specFo / specRep));
}

TEST(Estimator, ParsesNames) {
  EXPECT_EQ(parseEstimator("first-order"), Estimator::FirstOrder);
  EXPECT_EQ(parseEstimator("representative"), Estimator::Representative);
  EXPECT_STREQ(estimatorName(Estimator::FirstOrder), "first-order");
  EXPECT_THROW(parseEstimator("centroid"), Error);
}

}  // namespace
}  // namespace lc::lightcuts
