#include "render/reference_pixels.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lc
