// The pair of bounds must be clusterBounds' bounds, bit for bit: a cut that bounds two
// children together must refine exactly as one that bounds them one at a time.
#include "lightcuts/bounds_pair.h"

#include <gtest/gtest.h>

#include <bit>

#include "core/rng.h"
#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::Config;
using test_lights::randomConfig;

void expectSameBits(const Color& a, const Color& b, int config, const char* what) {
  for (int ch = 0; ch < 3; ++ch)
    ASSERT_EQ(std::bit_cast<uint32_t>(a[ch]), std::bit_cast<uint32_t>(b[ch]))
        << what << ", config " << config << ", channel " << ch << ": " << a[ch] << " vs " << b[ch];
}

class BoundsPair : public ::testing::TestWithParam<LightType> {};

TEST_P(BoundsPair, AreClusterBoundsBitForBit) {
  const LightType type = GetParam();
  ASSERT_TRUE(boundsPairApplies(type, false));
  Rng r(777, uint64_t(type));
  int lit = 0, smooth = 0;
  for (int i = 0; i < 20000; ++i) {
    // Two clusters seen from the first configuration's point, with its group.
    const Config a = randomConfig(r, type);
    const Config b = randomConfig(r, type);
    const LightGroup& g = a.set.groups[0];
    const BoundFrames fr(a.sp);
    ChildBounds pair[2];
    clusterBoundsPair(a.node, b.node, type, g, a.sp, fr, pair);
    for (int k = 0; k < 2; ++k) {
      const LightNode& n = k ? b.node : a.node;
      Color lower;
      bool sm = false;
      const Color upper = clusterBounds(n, type, g, a.sp, fr, &lower, &sm);
      expectSameBits(pair[k].upper, upper, i, "upper");
      expectSameBits(pair[k].lower, lower, i, "lower");
      ASSERT_EQ(pair[k].smooth, sm) << "config " << i;
      lit += luminance(upper) > 0;
      smooth += sm;
    }
  }
  // The configurations must reach the lit and the smooth cases (spots are never smooth).
  EXPECT_GT(lit, 5000);
  if (type != LightType::Spot) {
    EXPECT_GT(smooth, 1000);
  }
}

INSTANTIATE_TEST_SUITE_P(PairedKinds, BoundsPair, ::testing::Values(LightType::Omni, LightType::Oriented, LightType::Spot),
                         [](const auto& info) { return std::string(lightTypeName(info.param)); });

TEST(BoundsPair, AppliesToPointLightTreesOfOneGroup) {
  EXPECT_TRUE(boundsPairApplies(LightType::Omni, false));
  EXPECT_TRUE(boundsPairApplies(LightType::Oriented, false));
  EXPECT_TRUE(boundsPairApplies(LightType::Spot, false));
  EXPECT_FALSE(boundsPairApplies(LightType::Omni, true));
  EXPECT_FALSE(boundsPairApplies(LightType::Directional, false));
}

}  // namespace
}  // namespace lc::lightcuts
