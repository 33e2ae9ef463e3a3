#include "lights/vpl.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "io/ray_parser.h"
#include "test_scenes.h"

namespace lc::lights {
namespace {

using lc::testing::closedBox;  // albedo a, 20 units wide, one point light of intensity I

TEST(Vpl, OneBounceCarriesAlbedoTimesEmittedPower) {
  auto s = closedBox(0.5f, 2.0f);
  VplOptions o;
  o.count = 20000;
  VplInfo info = addVpls(*s, o);
  EXPECT_EQ(info.paths, 20000u);
  EXPECT_EQ(info.vpls, 20000u);  // every path hits a wall
  EXPECT_EQ(s->lights().size(), 20001u);
  double emitted = 4 * kPi * 2.0;
  EXPECT_NEAR(info.power.x / (0.5 * emitted), 1.0, 0.02);
  // The VPL intensities sum to the reflected power / pi (before the clamp's rescaling).
  const LightGroup& g = s->lights().groups[s->lights().lights.back().group];
  EXPECT_TRUE(g.isVpl);
  EXPECT_TRUE(g.diffuseOnly);
}

TEST(Vpl, BouncesFollowTheGeometricSeries) {
  auto s = closedBox(0.6f, 1.0f);
  VplOptions o;
  o.count = 40000;
  o.bounces = 3;
  VplInfo info = addVpls(*s, o);
  double emitted = 4 * kPi;
  double expect = emitted * (0.6 + 0.36 + 0.216);
  EXPECT_NEAR(info.power.y / expect, 1.0, 0.02);
  EXPECT_GT(info.vpls, 40000u);
}

TEST(Vpl, SameSeedSameVpls) {
  auto a = closedBox(0.5f, 1.0f), b = closedBox(0.5f, 1.0f);
  VplOptions o;
  o.count = 3000;
  o.bounces = 2;
  addVpls(*a, o);
  addVpls(*b, o);
  ASSERT_EQ(a->lights().size(), b->lights().size());
  for (size_t i = 0; i < a->lights().size(); ++i) {
    ASSERT_EQ(a->lights().lights[i].position, b->lights().lights[i].position);
    ASSERT_EQ(a->lights().lights[i].intensity, b->lights().lights[i].intensity);
  }
}

// The VPLs lie in the light array by cells of space (their Morton code's top bits in the
// scene's box), the same lights in the same order on one thread or several.
TEST(Vpl, VplsLieByCellsOfSpaceWhateverTheThreadCount) {
  auto a = closedBox(0.5f, 1.0f), b = closedBox(0.5f, 1.0f);
  VplOptions o;
  o.count = 30000;
  o.bounces = 2;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    addVpls(*a, o);
  }
  {
    tbb::global_control four(tbb::global_control::max_allowed_parallelism, 4);
    addVpls(*b, o);
  }
  const LightSet &la = a->lights(), &lb = b->lights();
  ASSERT_EQ(la.size(), lb.size());
  const Bounds3 box = a->bounds();
  uint32_t lastCell = 0;
  size_t vpls = 0;
  for (size_t i = 0; i < la.size(); ++i) {
    ASSERT_EQ(la.lights[i].position, lb.lights[i].position) << i;
    ASSERT_EQ(la.lights[i].intensity, lb.lights[i].intensity) << i;
    if (!la.groups[la.lights[i].group].isVpl) continue;
    const uint32_t cell = mortonCode(la.lights[i].position, box) >> 15;
    EXPECT_GE(cell, lastCell) << "VPL " << i << " is out of its cell's order";
    lastCell = cell;
    ++vpls;
  }
  EXPECT_GT(vpls, 30000u);
}

TEST(Vpl, ClampIsTheAttenuationOfEveryMethod) {
  auto s = closedBox(0.5f, 1.0f);
  VplOptions o;
  o.count = 100;
  o.clamp = 0.1f;
  VplInfo info = addVpls(*s, o);
  float dc = 0.1f * s->bounds().diagonal() / 2;
  EXPECT_NEAR(info.clampDistance, dc, 1e-4f);
  const Light& v = s->lights().lights.back();
  const LightGroup& g = s->lights().groups[v.group];
  // Intensity times attenuation is I * min(1/dc^2, 1/d^2) for the unscaled intensity I.
  float I = v.intensity.x * dc * dc;
  for (float d : {0.1f * dc, 0.5f * dc, dc, 2 * dc, 10 * dc})
    EXPECT_NEAR(v.intensity.x * g.atten(d), I * std::min(1 / (dc * dc), 1 / (d * d)), 1e-5f * I / (dc * dc));
  // The Lightcuts bound uses the same attenuation: render/vpl_bound_test.cpp.
}

TEST(Vpl, SeedNormalisationDividesByVplsOnTheObject) {
  auto s = closedBox(0.5f, 2.0f);
  VplOptions o;
  o.count = 500;
  o.clamp = 0;
  o.normalize = VplNormalize::Object;
  addVpls(*s, o);
  // One object (the box): each VPL = total light intensity * kd / 500.
  const Light& v = s->lights().lights.back();
  EXPECT_NEAR(v.intensity.x, 2.0f * 0.5f / 500, 1e-6f);
}

TEST(Vpl, LimitsAndBadOptions) {
  auto s = closedBox(0.5f, 1.0f);
  VplOptions o;
  o.count = 1000;
  o.maxVpls = 100;
  try {
    addVpls(*s, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--max-vpls"), std::string::npos);
  }
  o.maxVpls = 1000000;
  o.clamp = -1;
  EXPECT_THROW(addVpls(*s, o), Error);
  EXPECT_EQ(s->lights().size(), 1u);
}

TEST(Vpl, SpotAndDirectionalLightsShootIntoTheirCones) {
  auto s = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
spot_light { position = (0, 0, 5); direction = (0, 0, -1); colour = (1, 1, 1); cutoff = 20; }
directional_light { direction = (0, 0, -1); colour = (1e-6, 1e-6, 1e-6); }
scale(100, square { material = { diffuse = (0.5, 0.5, 0.5); }; })
)", "s.ray", ""));
  VplOptions o;
  o.count = 2000;
  addVpls(*s, o);
  size_t inCone = 0, vpls = 0;
  for (const Light& l : s->lights().lights) {
    if (l.type != LightType::Oriented) continue;
    ++vpls;
    inCone += std::hypot(l.position.x, l.position.y) <= 5 * std::tan(20 * kPi / 180) + 1e-3f;
  }
  EXPECT_GT(vpls, 1000u);
  // The spot's VPLs all land inside its cone; the dim directional light's are few.
  EXPECT_GT(double(inCone) / double(vpls), 0.9);
}

}  // namespace
}  // namespace lc::lights
