// VPLs (lights/) seen by the Lightcuts bounds (lightcuts/): here in render, the first layer
// that sees both, so that lights/ includes nothing of lightcuts/.
#include <gtest/gtest.h>

#include "lightcuts/bounds.h"
#include "lightcuts/light_tree.h"
#include "lights/vpl.h"
#include "test_scenes.h"

namespace lc {
namespace {

using lc::testing::closedBox;  // albedo a, 20 units wide, one point light of intensity I

// The VPL clamp is the attenuation of every method (lights/vpl_test.cpp checks the
// group's): the Lightcuts bound of a one-VPL cluster uses it too, so it is >= the exact
// contribution, and tight for one light.
TEST(VplBound, OneVplClusterBoundUsesTheClamp) {
  auto s = closedBox(0.5f, 1.0f);
  lights::VplOptions o;
  o.count = 100;
  o.clamp = 0.1f;
  lights::VplInfo info = lights::addVpls(*s, o);
  const float dc = info.clampDistance;
  ASSERT_GT(dc, 0);
  const Light& v = s->lights().lights.back();
  const LightGroup& g = s->lights().groups[v.group];
  ASSERT_TRUE(g.isVpl);
  lightcuts::LightNode node{};
  node.lo = node.hi = v.position;
  node.axis = v.direction;
  node.cosHalfAngle = 1;
  node.intensity = v.intensity;
  lightcuts::ShadingPoint sp;
  sp.p = v.position + v.direction * (0.3f * dc) + Vec3(0.01f, 0.02f, 0.0f);
  sp.n = -v.direction;
  sp.r = sp.n;
  sp.kd = Color(1);
  Color mg;
  Vec3 wi;
  float dist;
  ASSERT_TRUE(lightcuts::lightContribution(v, g, sp, mg, wi, dist));
  Color exact = mg * v.intensity;
  Color bound = lightcuts::clusterBound(node, LightType::Oriented, g, sp, lightcuts::BoundFrames(sp));
  EXPECT_GE(bound.x, exact.x);
  EXPECT_LE(bound.x, exact.x * 1.01f);
}

}  // namespace
}  // namespace lc
