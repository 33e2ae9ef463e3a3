#include "lightcuts/merged_batch.h"

#include <gtest/gtest.h>

#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::randomUnit;

// The per-node path: one light's unshadowed contribution.
Color scalarNode(const Light& rep, const LightGroup& g, const ShadingPoint& sp, const Color& intensity) {
  Color mg;
  Vec3 wi;
  float dist;
  if (!lightContribution(rep, g, sp, mg, wi, dist)) return Color(0);
  return mg * intensity;
}

// Random nodes of every supported kind and group, at random receivers (diffuse, specular,
// shininess 0): the four-lane sum equals the per-node one.
TEST(MergedBatch, EqualsThePerNodePath) {
  Rng r(8, 8);
  for (int trial = 0; trial < 300; ++trial) {
    LightSet set;
    MergedBatch b;
    Color want(0);
    ShadingPoint sp = test_lights::point(Vec3(0, 0, 0));
    sp.n = randomUnit(r);
    sp.r = randomUnit(r);
    const float shininess[] = {0, 0.5f, 1, 7, 20, 60};
    sp.shininess = shininess[r.below(6)];
    if (r.below(3) == 0) sp.ks = Color(0);
    int n = 1 + int(r.below(11));  // not a multiple of four: the last block is padded
    for (int i = 0; i < n; ++i) {
      LightType type = r.below(2) ? LightType::Oriented : LightType::Omni;
      LightGroup g = test_lights::randomGroup(r, type);
      Light l;
      l.type = type;
      l.position = randomUnit(r) * (0.3f + 3 * r.uniform());
      l.direction = randomUnit(r);
      Color intensity(r.uniform(), r.uniform(), r.uniform());
      b.add(l, g, intensity);
      want += scalarNode(l, g, sp, intensity);
    }
    Color got = evaluateBatch(b, sp);
    // And block by block.
    Color parts(0);
    for (size_t k = 0; k < b.blocks.size(); ++k) parts += evaluateBatch(b, sp, k, k + 1);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(parts[c], got[c], 1e-5f * (std::fabs(got[c]) + 1e-3f));
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(got[c], want[c], 2e-5f * (std::fabs(want[c]) + 1e-3f)) << "trial " << trial << " channel " << c;
  }
}

TEST(MergedBatch, EmptyBatchGivesNothing) {
  MergedBatch b;
  EXPECT_EQ(luminance(evaluateBatch(b, test_lights::point(Vec3(0, 0, 0)))), 0.0f);
  b.add(Light{}, LightGroup{}, Color(1));
  b.clear();
  EXPECT_EQ(b.count, 0u);
  EXPECT_TRUE(b.blocks.empty());
}

}  // namespace
}  // namespace lc::lightcuts
