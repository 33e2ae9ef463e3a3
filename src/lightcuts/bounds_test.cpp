// Property tests: every cluster bound must be >= the true sum of the cluster's unshadowed
// contributions, over thousands of random configurations of each light kind.
#include "lightcuts/bounds.h"

#include <gtest/gtest.h>

#include "core/rng.h"
#include "test_lights.h"
#include "lightcuts/light_tree.h"

namespace lc::lightcuts {
namespace {

using test_lights::Config;
using test_lights::randomConfig;
using test_lights::randomInCone;
using test_lights::randomUnit;
using test_lights::trueSum;

class BoundProperty : public ::testing::TestWithParam<LightType> {};

TEST_P(BoundProperty, BoundIsAtLeastTheTrueSum) {
  LightType type = GetParam();
  Rng r(12345, uint64_t(type));
  int nonZero = 0;
  for (int i = 0; i < 20000; ++i) {
    Config c = randomConfig(r, type);
    BoundFrames fr(c.sp);
    Color b = clusterBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color t = trueSum(c);
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_GE(b[ch] * (1 + 1e-5f) + 1e-12f, t[ch])
          << "config " << i << " channel " << ch << " type " << lightTypeName(type);
    nonZero += luminance(t) > 0;
  }
  // The random configurations must actually exercise lit cases.
  EXPECT_GT(nonZero, 2000);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, BoundProperty,
                         ::testing::Values(LightType::Omni, LightType::Oriented, LightType::Spot,
                                           LightType::Directional),
                         [](const auto& info) { return std::string(lightTypeName(info.param)); });

TEST(CosBoundBox, BoundsSampledDirections) {
  Rng r(3, 3);
  for (int i = 0; i < 5000; ++i) {
    Vec3 lo(4 * r.uniform() - 2, 4 * r.uniform() - 2, 4 * r.uniform() - 2);
    Vec3 hi = lo + Vec3(r.uniform(), r.uniform(), r.uniform()) * 2;
    Frame f = makeFrame(randomUnit(r));
    float b = cosBoundBox(f, lo, hi);
    for (int k = 0; k < 50; ++k) {
      Vec3 q = lo + (hi - lo) * Vec3(r.uniform(), r.uniform(), r.uniform());
      if (length2(q) == 0) continue;
      ASSERT_GE(b + 1e-6f, dot(normalize(q), f.w));
    }
  }
}

TEST(CosBoundBox, IsTightForAPointOnTheAxis) {
  Frame f = makeFrame(Vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(cosBoundBox(f, Vec3(0, 0, 2), Vec3(0, 0, 2)), 1.0f);
  EXPECT_FLOAT_EQ(cosBoundBox(f, Vec3(0, 0, -2), Vec3(0, 0, -1)), 0.0f);
  // A point at 45 degrees gives cos 45.
  EXPECT_NEAR(cosBoundBox(f, Vec3(1, 0, 1), Vec3(1, 0, 1)), std::sqrt(0.5f), 1e-6f);
}

// The lower cosine from the box's nearest projection (RotatedBox::cosLower) holds at
// every point of the box, in any frame, and is the exact least cosine for a box seen
// head-on: 0.96 for a unit cube 2.5 to 3.5 above the point, where the smallest projection
// over the longest vector gives 0.70 (and the cube's corners are at 0.962).
TEST(RotatedBox, CosLowerBoundsSampledDirections) {
  Rng r(4, 4);
  int positive = 0;
  for (int i = 0; i < 5000; ++i) {
    Vec3 lo(4 * r.uniform() - 2, 4 * r.uniform() - 2, 4 * r.uniform() - 2);
    Vec3 hi = lo + Vec3(r.uniform(), r.uniform(), r.uniform()) * 2;
    Frame f = makeFrame(randomUnit(r));
    const float b = RotatedBox(f, (lo + hi) * 0.5f, (hi - lo) * 0.5f).cosLower();
    if (!(b > 0)) continue;  // 0: some direction may be at 90 degrees or more
    ++positive;
    for (int k = 0; k < 50; ++k) {
      Vec3 q = lo + (hi - lo) * Vec3(r.uniform(), r.uniform(), r.uniform());
      if (length2(q) == 0) continue;
      ASSERT_LE(b, dot(normalize(q), f.w) + 1e-6f);
    }
  }
  EXPECT_GT(positive, 500);
  const Frame up = makeFrame(Vec3(0, 1, 0));
  const RotatedBox cube(up, Vec3(0, 3, 0), Vec3(0.5f));
  const float corner = 2.5f / std::sqrt(2.5f * 2.5f + 0.5f);
  EXPECT_NEAR(cube.cosLower(), corner, 1e-6f);
  EXPECT_LT(2.5f / length(Vec3(0.5f, 3.5f, 0.5f)), 0.71f);
}

TEST(ConeWiden, WidensByTheHalfAngle) {
  float c = coneWiden(std::cos(1.0f), std::cos(0.25f), std::sin(0.25f));
  EXPECT_NEAR(c, std::cos(0.75f), 1e-5f);
  EXPECT_EQ(coneWiden(0.9f, 0.5f, std::sqrt(0.75f)), 1.0f);
  EXPECT_EQ(coneWiden(-0.5f, -1.0f, 0.0f), 1.0f);
}

TEST(ConeUnion, ContainsBothCones) {
  Rng r(9, 9);
  for (int i = 0; i < 2000; ++i) {
    Vec3 a = randomUnit(r), b = randomUnit(r);
    float ca = std::cos(kPi * r.uniform() * 0.5f), cb = std::cos(kPi * r.uniform() * 0.5f);
    Vec3 axis;
    float cu;
    coneUnion(a, ca, b, cb, axis, cu);
    for (int k = 0; k < 20; ++k) {
      Vec3 da = randomInCone(r, a, std::acos(ca));
      Vec3 db = randomInCone(r, b, std::acos(cb));
      ASSERT_GE(dot(da, axis), cu - 1e-4f);
      ASSERT_GE(dot(db, axis), cu - 1e-4f);
    }
  }
}

// A cluster of oriented lights that all face away from the point, by more than the cone's
// half-angle, reaches it with nothing: the bound is exactly 0, however far past 90 degrees
// they face (a cosine below 0 is kept through the cone widening, not clamped to 0 first,
// which left sin(half-angle) for the far side of every luminous sphere).
TEST(ClusterBound, LightsFacingAwayGiveZero) {
  for (float away : {1.8f, 2.2f, 3.0f}) {  // angle between the cone's axis and the point, radians
    LightNode node;
    node.lo = Vec3(-0.05f, -0.05f, -0.05f);
    node.hi = Vec3(0.05f, 0.05f, 0.05f);
    node.axis = Vec3(std::sin(away), 0, std::cos(away));  // the point is along +z
    node.cosHalfAngle = std::cos(0.1f);
    node.intensity = Color(1);
    ShadingPoint sp;
    sp.p = Vec3(0, 0, 5);
    sp.n = Vec3(0, 0, -1);  // facing the cluster
    sp.r = sp.n;
    sp.kd = Color(1);
    LightGroup g;
    BoundFrames fr(sp);
    EXPECT_EQ(luminance(clusterBound(node, LightType::Oriented, g, sp, fr)), 0.0f) << "away " << away;
    // Turned toward the point within the half-angle, it is lit again.
    node.axis = Vec3(std::sin(away - 1.5f), 0, std::cos(away - 1.5f));
    if (away - 1.5f < 1.4f) {
      EXPECT_GT(luminance(clusterBound(node, LightType::Oriented, g, sp, fr)), 0.0f) << "away " << away;
    }
  }
}

// The lower bound never exceeds the true unshadowed sum (and so brackets it with the upper).
TEST_P(BoundProperty, LowerBoundIsAtMostTheTrueSum) {
  LightType type = GetParam();
  Rng r(777, uint64_t(type));
  int positive = 0;
  for (int i = 0; i < 20000; ++i) {
    Config c = randomConfig(r, type);
    BoundFrames fr(c.sp);
    Color lb = clusterLowerBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color ub = clusterBound(c.node, type, c.set.groups[0], c.sp, fr);
    Color t = trueSum(c);
    for (int ch = 0; ch < 3; ++ch) {
      ASSERT_LE(lb[ch], t[ch] * (1 + 1e-5f) + 1e-12f) << "config " << i << " type " << lightTypeName(type);
      ASSERT_LE(lb[ch], ub[ch] + 1e-12f);
    }
    positive += luminance(lb) > 0;
  }
  EXPECT_GT(positive, 500);  // and is not trivially zero
}

// `smooth` promises that no light of the cluster sits at a clamp of the contribution: every
// cosine positive and the attenuation on one side of its corner, within its range
// (directional lights: their direction's cosines; no attenuation). Spot lights never are.
TEST_P(BoundProperty, SmoothMeansNoClampWithinTheCluster) {
  LightType type = GetParam();
  Rng r(4242, uint64_t(type));
  int smoothCount = 0;
  for (int i = 0; i < 20000; ++i) {
    Config c = randomConfig(r, type);
    BoundFrames fr(c.sp);
    Color lower;
    bool smooth = true;
    clusterBounds(c.node, type, c.set.groups[0], c.sp, fr, &lower, &smooth);
    if (!smooth) continue;
    ++smoothCount;
    ASSERT_TRUE(type == LightType::Omni || type == LightType::Oriented || type == LightType::Directional)
        << lightTypeName(type);
    const LightGroup& g = c.set.groups[0];
    int flat = 0;
    for (const Light& l : c.set.lights) {
      const bool dir = type == LightType::Directional;
      Vec3 d = l.position - c.sp.p;
      float dist = dir ? 0.0f : length(d);
      Vec3 w = dir ? -l.direction : d / dist;
      ASSERT_GT(dot(c.sp.n, w), 0) << "config " << i;
      if (type == LightType::Oriented) {
        ASSERT_GT(-dot(l.direction, w), 0) << "config " << i;
      }
      if (!g.diffuseOnly && c.sp.hasSpecular()) {
        ASSERT_GT(dot(c.sp.r, w), 0) << "config " << i;
      }
      ASSERT_LE(dist, g.atten.maxDistance);
      flat += g.atten.derivative(dist) == 0;
    }
    ASSERT_TRUE(flat == 0 || flat == int(c.set.lights.size())) << "config " << i;
  }
  if (type == LightType::Omni || type == LightType::Oriented) {
    EXPECT_GT(smoothCount, 500);
  } else if (type == LightType::Directional) {
    EXPECT_GT(smoothCount, 100);  // clusters of directions wholly above the horizon
  } else {
    EXPECT_EQ(smoothCount, 0);
  }
}

// An environment's worth of directional lights (issue 24): thousands over the whole sphere
// of directions, denser in a "sky" cap and a "sun" spot, clustered by the agglomerative
// builder. At random shading points every node of the tree, from the root (lights on all
// sides of the surface) to the leaves, has lower <= true unshadowed sum <= upper, with and
// without the nodes' cones of directions.
TEST(DirectionalTreeBounds, EveryNodeOfAnEnvironmentTreeBracketsItsLights) {
  Rng r(2024, 24);
  LightSet set;
  LightGroup g;
  g.atten = Attenuation{0, 0, 0, kInf};
  set.groups.push_back(g);
  const Vec3 sun = normalize(Vec3(0.3f, 0.8f, -0.5f));
  for (int i = 0; i < 4096; ++i) {
    Light l;
    l.type = LightType::Directional;
    l.group = 0;
    Vec3 toLight = i % 4 == 0 ? randomInCone(r, sun, 0.05f)
                   : i % 4 == 1 ? randomInCone(r, Vec3(0, 1, 0), 1.2f)
                                : randomUnit(r);
    l.direction = -toLight;
    float s = 0.5f + r.uniform();
    l.intensity = Color(0.3f + r.uniform(), 0.5f, 0.3f + r.uniform()) * (s / 4096);
    set.lights.push_back(l);
  }
  std::vector<uint32_t> idx(set.lights.size());
  for (uint32_t i = 0; i < idx.size(); ++i) idx[i] = i;
  LightTree tree = buildAgglomerativeTree(set, idx, LightType::Directional, 0, 1);
  ASSERT_EQ(tree.nodes.size(), idx.size() - 1);
  // The same tree with the cones of directions buildLightForest gives directional trees:
  // both must bracket every node's sum.
  LightTree coned = tree;
  computeDirectionCones(set, coned);
  const LightTree* trees[2] = {&tree, &coned};
  double spread[2] = {0, 0};
  const std::vector<NodeRef> all = tree.preorderNodes();
  std::vector<Color> sum(tree.nodes.size());  // per inner node
  int lit = 0;
  for (int k = 0; k < 300; ++k) {
    ShadingPoint sp;
    sp.p = Vec3(10 * r.uniform() - 5, 10 * r.uniform() - 5, 10 * r.uniform() - 5);
    sp.n = randomUnit(r);
    Vec3 v = randomUnit(r);
    if (dot(v, sp.n) < 0) v = -v;
    sp.r = normalize(reflect(v, sp.n));
    sp.kd = Color(r.uniform(), r.uniform(), r.uniform());
    sp.ks = r.below(2) ? Color(0) : Color(r.uniform(), r.uniform(), r.uniform());
    const float shininess[] = {0, 1, 10, 64, 128};
    sp.shininess = shininess[r.below(5)];
    BoundFrames fr(sp);
    // A node's sum: a leaf's light, an inner node's children (slots after their parent's:
    // summed bottom-up).
    auto sumOf = [&](NodeRef r) {
      if (!isLeafRef(r)) return sum[r];
      const Light& l = set.lights[leafLight(r)];
      Color mg;
      Vec3 wi;
      float d;
      return lightContribution(l, g, sp, mg, wi, d) ? mg * l.intensity : Color(0);
    };
    for (size_t i = tree.nodes.size(); i-- > 0;)
      sum[i] = sumOf(tree.nodes[i].left(NodeRef(i))) + sumOf(tree.nodes[i].right(NodeRef(i)));
    for (int c = 0; c < 2; ++c)
      for (NodeRef i : all) {
        Color lower;
        Color upper = clusterBounds(trees[c]->node(set, i), LightType::Directional, g, sp, fr, &lower);
        const Color want = sumOf(i);
        for (int ch = 0; ch < 3; ++ch) {
          ASSERT_GE(upper[ch] * (1 + 1e-5f) + 1e-12f, want[ch]) << "point " << k << " node " << i << " cones " << c;
          ASSERT_LE(lower[ch], want[ch] * (1 + 1e-5f) + 1e-12f) << "point " << k << " node " << i << " cones " << c;
        }
        if (!isLeafRef(i) && tree.nodes[i].lights() <= 256) spread[c] += luminance(upper - lower);
      }
    lit += luminance(sum[0]) > 0;
  }
  EXPECT_GT(lit, 250);
  // The cones tighten the bounds: the summed spread (upper - lower) over the inner nodes of
  // up to 256 lights (what cuts end in) and every point shrinks (by 4.5% here: the boxes,
  // bounded as boxes of unit vectors, are already close).
  EXPECT_LT(spread[1], 0.98 * spread[0]) << spread[1] / spread[0];
  RecordProperty("spread_ratio_with_cones", std::to_string(spread[1] / spread[0]));
}

}  // namespace
}  // namespace lc::lightcuts
