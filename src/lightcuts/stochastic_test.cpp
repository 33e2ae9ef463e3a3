#include <gtest/gtest.h>

#include <cmath>

#include "lightcuts/evaluator.h"
#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::cloud;
using test_lights::point;

// Blocks every direction with a negative x component: half the cloud is hidden, and many
// clusters are partly hidden (what makes lightcuts refine in occluded interiors).
struct HalfBlocked : Visibility {
  Color operator()(const Vec3& wi, float) override { return wi.x < 0 ? Color(0) : Color(1); }
};

// Stochastic lightcuts are unbiased: over many independent draws (seeds), the mean
// estimate is brute force's sum, within the statistical tolerance the draws' own spread
// gives (4 standard errors), for omni and oriented clouds and several cut sizes.
TEST(StochasticLightcuts, MeanOfManyDrawsIsBruteForce) {
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    LightSet s = cloud(3000, type, 11);
    LightForest f = buildLightForest(s);
    ShadingPoint sp = point(Vec3(0.1f, -0.2f, 0));
    HalfBlocked vis;
    EvalStats st;
    const double exact = double(luminance(makeBruteForce(s)->evaluate(sp, vis, st).radiance));
    ASSERT_GT(exact, 0);
    for (int cut : {1, 8, 64}) {
      SCOPED_TRACE("type " + std::to_string(int(type)) + " cut " + std::to_string(cut));
      CutOptions o;
      o.stochasticCut = cut;
      constexpr int kDraws = 4000;
      double sum = 0, sum2 = 0;
      for (int i = 0; i < kDraws; ++i) {
        o.seed = uint64_t(i) + 1;
        double v = double(luminance(makeStochasticLightcuts(s, f, o)->evaluate(sp, vis, st).radiance));
        sum += v;
        sum2 += v * v;
      }
      const double mean = sum / kDraws, var = std::max(0.0, sum2 / kDraws - mean * mean);
      const double stderr_ = std::sqrt(var / kDraws);
      EXPECT_NEAR(mean, exact, 4 * stderr_ + 1e-6 * exact) << "mean " << mean << " exact " << exact;
      // Larger cuts draw fewer lights per cluster: less spread (not a property of a single
      // draw, but of the estimator; 64 clusters of ~50 lights vs one of 3000).
      if (cut == 64) {
        EXPECT_LT(std::sqrt(var), 0.5 * exact);
      }
    }
  }
}

// The cut has the size asked for (or every light, when there are fewer), one shadow ray
// at most per cluster, and the same seed gives the same value.
TEST(StochasticLightcuts, CutSizeRaysAndDeterminism) {
  LightSet s = cloud(500, LightType::Omni, 3);
  LightForest f = buildLightForest(s);
  ShadingPoint sp = point(Vec3(0, 0, 0));
  HalfBlocked vis;
  CutOptions o;
  o.stochasticCut = 32;
  EvalStats st;
  auto ev = makeStochasticLightcuts(s, f, o);
  EvalResult a = ev->evaluate(sp, vis, st);
  EXPECT_LE(a.cutSize, 32u);
  EXPECT_GE(a.cutSize, 16u);  // clusters behind the surface (zero bound) are dropped
  EXPECT_LE(st.shadowRays, uint64_t(a.cutSize));
  EvalResult b = ev->evaluate(sp, vis, st);
  EXPECT_EQ(a.radiance, b.radiance);
  o.stochasticCut = 100000;  // more than the lights: every light with a non-zero bound, exact
  EvalStats st2;
  EvalResult all = makeStochasticLightcuts(s, f, o)->evaluate(sp, vis, st2);
  EvalResult exact = makeBruteForce(s)->evaluate(sp, vis, st2);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(all.radiance[k], exact.radiance[k], 1e-5f * exact.radiance[k]);
}

TEST(StochasticLightcuts, ParsesItsName) {
  EXPECT_EQ(parseMethod("stochastic"), Method::Stochastic);
  EXPECT_STREQ(methodName(Method::Stochastic), "stochastic");
}

}  // namespace
}  // namespace lc::lightcuts
