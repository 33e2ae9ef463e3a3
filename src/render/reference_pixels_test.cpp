#include "render/reference_pixels.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "io/image_metrics.h"
#include "io/ray_parser.h"
#include "lightcuts/light_tree.h"
#include "lights/vpl.h"
#include "render/renderer.h"
#include "test_scenes.h"

namespace lc {
namespace {

// The clamp's share measured over every VPL, and over every eighth (what millions of VPLs
// get: 16 points x 8.1M VPLs was 8 s for this one summary figure): the strided subset
// estimates the same ratio.
TEST(VplClampedFraction, StridedSubsetOfVplsEstimatesTheSameShare) {
  auto s = testing::closedBox(0.6f, 1.0f);
  lights::VplOptions v;
  v.count = 20000;
  v.clamp = 1.0f;  // a strong clamp (17 units in a box of 20): a share well above zero
  lights::VplInfo info = lights::addVpls(*s, v);
  ASSERT_GT(info.vpls, 10000u);
  render::RenderOptions o;
  o.width = o.height = 32;
  const double all = render::vplClampedFraction(*s, o, 16, uint64_t(16) * info.vpls);
  const double strided = render::vplClampedFraction(*s, o, 16, uint64_t(16) * info.vpls / 8);
  ASSERT_GT(all, 0.02) << "the clamp removes a measurable share";
  EXPECT_LT(all, 0.9);
  EXPECT_NEAR(strided, all, 0.02 * all);  // 0.2% apart here
  EXPECT_NE(strided, all) << "the cap did not stride the VPLs";
}

// The worst reference pixels (--stats: worst_pixels) are where the error is: worst first,
// the first one the maximum error, each one's test luminance the image's own at (x, y),
// its reference the brute-force image's there, and its error theirs.
TEST(ReferencePixels, WorstPixelsAreTheLargestErrorsAtTheirPlaces) {
  auto s = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
point_light { position = (0.3, 0.2, 3); colour = (1, 1, 1); }
point_light { position = (-0.4, 0.1, 3); colour = (0.5, 0.5, 1); }
point_light { position = (1.5, -1, 2); colour = (0.2, 1, 0.4); }
point_light { position = (-1, 1.4, 2.5); colour = (1, 0.3, 0.3); }
scale(10, square { material = { diffuse = (0.7, 0.7, 0.7); }; })
translate(0, 0, 1, scale(1.2, square { material = { diffuse = (0.9, 0.2, 0.2); }; }))
)", "worst.ray", ""));
  lightcuts::LightForest forest = lightcuts::buildLightForest(s->lights());
  lightcuts::CutOptions co;
  co.errorRatio = 0.5f;  // coarse cuts: errors of many sizes
  co.estimator = lightcuts::Estimator::Representative;
  auto lc = lightcuts::makeLightcuts(s->lights(), forest, co);
  auto brute = lightcuts::makeBruteForce(s->lights());
  render::RenderOptions o;
  o.width = o.height = 24;
  o.aa = render::AntiAliasing::Off;
  o.referencePixels = 24 * 24;
  render::RenderResult r = render::render(*s, *lc, o);
  o.referencePixels = 0;
  render::RenderResult ref = render::render(*s, *brute, o);
  const render::ReferenceStats& rs = r.stats.reference;
  ASSERT_EQ(rs.worst.size(), render::ReferenceStats::kWorstPixels);
  EXPECT_GT(rs.maxRelativeError, 0.01) << "the coarse cuts err somewhere";
  EXPECT_DOUBLE_EQ(rs.worst.front().relativeError, rs.maxRelativeError);
  double mean = 0;
  for (const Color& c : ref.image.pixels) mean += luminance(c);
  mean /= double(ref.image.pixels.size());
  for (size_t k = 0; k < rs.worst.size(); ++k) {
    const render::ReferenceStats::Pixel& p = rs.worst[k];
    if (k > 0) {
      EXPECT_LE(p.relativeError, rs.worst[k - 1].relativeError);
    }
    const size_t i = size_t(p.y) * size_t(o.width) + size_t(p.x);
    EXPECT_EQ(p.test, luminance(r.image.pixels[i]));
    EXPECT_NEAR(p.reference, luminance(ref.image.pixels[i]), 1e-5f * std::max(1.0f, p.reference));
    EXPECT_NEAR(p.relativeError, io::relativeError(p.reference, p.test, 0.01 * mean), 1e-3 * p.relativeError + 1e-7);
  }
}

}  // namespace
}  // namespace lc
