#include "lightcuts/cluster.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/bounds.h"
#include "test_lights.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <thread>
#include <map>
#include <set>

#include "core/rng.h"

namespace lc::lightcuts {
namespace {

using test_lights::leafCount;
using test_lights::rootLeft;
using test_lights::rootRight;

LightSet randomLights(size_t n, LightType type, uint64_t seed, bool coloured = false) {
  LightSet s;
  s.groups.push_back(LightGroup{});
  Rng r(seed, 1);
  for (size_t i = 0; i < n; ++i) {
    Light l;
    l.type = type;
    l.position = Vec3(r.uniform(), r.uniform(), r.uniform()) * 10;
    l.direction = normalize(Vec3(r.uniform() - 0.5f, r.uniform() - 0.5f, r.uniform() - 0.5f));
    l.intensity = coloured ? Color(r.uniform(), r.uniform(), r.uniform()) + Color(0.01f) : Color(1);
    s.lights.push_back(l);
  }
  return s;
}

// Every node's box, cone and intensity must cover its children, and every light
// must sit in exactly one leaf. Inner nodes sit in preorder: a left inner child in the
// next slot, a right one after the left subtree's inner nodes.
void checkTree(const LightSet& set, const LightTree& t) {
  std::set<uint32_t> leaves;
  uint32_t nextSlot = 0;
  std::function<uint32_t(NodeRef)> visit = [&](NodeRef r) -> uint32_t {  // returns the light count
    const LightNode n = t.node(set, r);
    if (isLeafRef(r)) {
      EXPECT_EQ(t.lightCount(r), 1u);
      EXPECT_EQ(n.rep, leafLight(r));
      EXPECT_TRUE(leaves.insert(n.rep).second) << "light in two leaves";
      const Light& l = set.lights[n.rep];
      Vec3 p = l.type == LightType::Directional ? -l.direction : l.position;
      EXPECT_EQ(n.lo, p);
      return 1;
    }
    EXPECT_EQ(r, nextSlot++) << "inner nodes in preorder";
    const NodeRef ra = n.left(r), rb = n.right(r);
    const LightNode a = t.node(set, ra), b = t.node(set, rb);
    EXPECT_TRUE(n.rep == a.rep || n.rep == b.rep) << "representative comes from a child";
    EXPECT_EQ(n.lights(), t.lightCount(ra) + t.lightCount(rb)) << "light counts add up";
    EXPECT_EQ(n.leftLights(), t.lightCount(ra));
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(n.lo[k], std::min(a.lo[k], b.lo[k]));
      EXPECT_GE(n.hi[k], std::max(a.hi[k], b.hi[k]));
      EXPECT_NEAR(n.intensity[k], a.intensity[k] + b.intensity[k], 1e-4f * n.intensity[k] + 1e-6f);
    }
    if (t.type == LightType::Oriented) {
      const Light& la = set.lights[a.rep];
      EXPECT_GE(dot(la.direction, n.axis), n.cosHalfAngle - 1e-4f);
    }
    uint32_t count = visit(ra);
    count += visit(rb);
    EXPECT_EQ(count, n.lights());
    return count;
  };
  ASSERT_FALSE(t.empty());
  EXPECT_EQ(visit(t.root), t.lightTotal);
  EXPECT_EQ(t.nodes.size(), leaves.size() - 1) << "inner nodes only";
  EXPECT_EQ(leaves.size(), t.lightTotal);
}

class TreeBuild : public ::testing::TestWithParam<std::tuple<TreeBuilder, LightType>> {};

TEST_P(TreeBuild, IsAValidClusterHierarchy) {
  auto [builder, type] = GetParam();
  for (size_t n : {1u, 2u, 3u, 17u, 1000u}) {
    LightSet set = randomLights(n, type, n, true);
    LightForest f = buildLightForest(set, TreeBuildOptions{builder, 5});
    ASSERT_EQ(f.trees.size(), 1u);
    checkTree(set, f.trees[0]);
    ASSERT_EQ(f.trees[0].moments.size(), f.trees[0].nodes.size());  // inner nodes only
    // Only the seed builder stores the seed's traversal data; others leave it to makeCourseCuts.
    ASSERT_EQ(f.trees[0].course.size(), builder == TreeBuilder::Course ? f.trees[0].nodes.size() : 0u);
  }
}

// The seed's traversal data that agglomerative trees no longer store: computed on demand,
// it equals what the build used to store, field for field.
TEST(TreeBuild, SeedDataOnDemandEqualsEager) {
  for (LightType type : {LightType::Omni, LightType::Oriented, LightType::Directional}) {
    LightSet set = randomLights(3000, type, 21, true);
    TreeBuildOptions eager{TreeBuilder::Agglomerative, 5};
    eager.courseData = true;
    LightForest a = buildLightForest(set, eager);
    LightForest b = buildLightForest(set, TreeBuildOptions{TreeBuilder::Agglomerative, 5});
    ASSERT_EQ(a.trees[0].course.size(), a.trees[0].nodes.size());
    ASSERT_TRUE(b.trees[0].course.empty());
    EXPECT_LT(b.memoryBytes(), a.memoryBytes());
    std::vector<CourseNodeData> lazy = courseNodeData(set, b.trees[0]);
    ASSERT_EQ(lazy.size(), a.trees[0].course.size());
    for (size_t i = 0; i < lazy.size(); ++i) {
      ASSERT_EQ(lazy[i].position, a.trees[0].course[i].position) << i;
      ASSERT_EQ(lazy[i].direction, a.trees[0].course[i].direction) << i;
      ASSERT_EQ(lazy[i].error, a.trees[0].course[i].error) << i;
    }
  }
}

TEST_P(TreeBuild, IsDeterministic) {
  auto [builder, type] = GetParam();
  LightSet set = randomLights(5000, type, 77, true);
  LightForest a = buildLightForest(set, TreeBuildOptions{builder, 5});
  LightForest b = buildLightForest(set, TreeBuildOptions{builder, 5});
  ASSERT_EQ(a.trees[0].nodes.size(), b.trees[0].nodes.size());
  for (size_t i = 0; i < a.trees[0].nodes.size(); ++i) {
    ASSERT_EQ(a.trees[0].nodes[i].rep, b.trees[0].nodes[i].rep);
    ASSERT_EQ(a.trees[0].nodes[i].a, b.trees[0].nodes[i].a);
    ASSERT_EQ(a.trees[0].nodes[i].b, b.trees[0].nodes[i].b);
  }
}

INSTANTIATE_TEST_SUITE_P(
    All, TreeBuild,
    ::testing::Combine(::testing::Values(TreeBuilder::Agglomerative, TreeBuilder::Course),
                       ::testing::Values(LightType::Omni, LightType::Oriented, LightType::Directional)),
    [](const auto& info) {
      return std::string(treeBuilderName(std::get<0>(info.param))) + "_" +
             lightTypeName(std::get<1>(info.param));
    });

TEST(TreeBuild, SeparatesGroupsAndTypes) {
  LightSet set = randomLights(100, LightType::Omni, 1);
  for (size_t i = 0; i < 30; ++i) set.lights[i].type = LightType::Oriented;
  LightGroup g2;
  g2.atten = Attenuation{1, 0, 0, kInf};
  uint16_t gi = set.groupFor(g2);
  for (size_t i = 30; i < 50; ++i) set.lights[i].group = gi;
  LightForest f = buildLightForest(set);
  ASSERT_EQ(f.trees.size(), 3u);
  size_t total = 0;
  for (const LightTree& t : f.trees) total += leafCount(t, t.root);
  EXPECT_EQ(total, 100u);
}

TEST(TreeBuild, SkipsLightsWithoutIntensity) {
  LightSet set = randomLights(10, LightType::Omni, 1);
  set.lights[3].intensity = Color(0);
  LightForest f = buildLightForest(set);
  EXPECT_EQ(leafCount(f.trees[0], f.trees[0].root), 9u);
}

// The lists of lights by (type, group) are the same whatever the block size the parallel
// gathering uses: runs of one group crossing blocks, groups absent from some blocks, dark
// lights skipped; each list in index order, the lists by (type, group).
TEST(TreeBuild, LightsByGroupIsTheSameForAnyBlockSize) {
  LightSet set = randomLights(200, LightType::Omni, 3);
  LightGroup g2;
  g2.atten = Attenuation{1, 0, 0, kInf};
  const uint16_t gi = set.groupFor(g2);
  for (size_t i = 0; i < set.lights.size(); ++i) {
    if (i % 7 < 3) set.lights[i].group = gi;  // runs of three
    if (i % 11 == 5) set.lights[i].type = LightType::Oriented;
    if (i % 13 == 4) set.lights[i].intensity = Color(0);
  }
  // What they must be: one pass in index order.
  std::map<std::pair<int, int>, std::vector<uint32_t>> expect;
  for (uint32_t i = 0; i < set.lights.size(); ++i)
    if (luminance(set.lights[i].intensity) > 0)
      expect[{int(set.lights[i].type), int(set.lights[i].group)}].push_back(i);
  for (size_t block : {size_t(1), size_t(2), size_t(5), size_t(64), size_t(1) << 20}) {
    std::vector<LightGroupList> got = lightsByGroup(set, block);
    ASSERT_EQ(got.size(), expect.size()) << block;
    size_t k = 0;
    for (const auto& [key, list] : expect) {
      EXPECT_EQ(int(got[k].type), key.first) << block;
      EXPECT_EQ(int(got[k].group), key.second) << block;
      EXPECT_EQ(got[k].lights, list) << block;
      ++k;
    }
  }
}

// computeMoments as it was, serial: the reference for the parallel one.
std::vector<NodeMoments> serialMoments(const LightSet& lights, const LightTree& tree) {
  struct Sums {
    double w = 0, n = 0;
    Vec3d pos, axis, posU, axisU;
  };
  std::vector<NodeMoments> m(tree.nodes.size());
  std::vector<std::pair<NodeRef, bool>> stack{{tree.root, false}};
  std::vector<Sums> done;
  while (!stack.empty()) {
    auto [i, expanded] = stack.back();
    stack.pop_back();
    const LightNode n = tree.node(lights, i);
    if (isLeafRef(i)) {
      const Light& l = lights.lights[n.rep];
      Sums s;
      s.w = 0.2126 * double(n.intensity.x) + 0.7152 * double(n.intensity.y) + 0.0722 * double(n.intensity.z);  // as computeMoments: in double
      s.n = 1;
      s.posU = Vec3d(l.type == LightType::Directional ? -l.direction : l.position);
      s.axisU = Vec3d(l.direction);
      s.pos = s.posU * s.w;
      s.axis = s.axisU * s.w;
      done.push_back(s);
      continue;
    }
    if (!expanded) {
      stack.emplace_back(i, true);
      stack.emplace_back(n.right(i), false);
      stack.emplace_back(n.left(i), false);
      continue;
    }
    Sums b = done.back();
    done.pop_back();
    Sums& s = done.back();
    s.w += b.w;
    s.n += b.n;
    s.pos += b.pos;
    s.axis += b.axis;
    s.posU += b.posU;
    s.axisU += b.axisU;
    Vec3d c = s.w > 0 ? s.pos / s.w : s.posU / s.n, a = s.w > 0 ? s.axis / s.w : s.axisU / s.n;
    m[i].centroid = c.toFloat();
    m[i].meanAxis = a.toFloat();
  }
  return m;
}

// The agglomerative builder lays the tree out in preorder, subtrees in parallel (checkTree),
// and sums the moments in parallel, large subtrees side by side: the same values, bit for
// bit, as the serial pass (computeMoments as it was).
TEST(Agglomerative, ParallelLayoutAndMomentsEqualSerialPasses) {
  for (LightType type : {LightType::Omni, LightType::Oriented, LightType::Directional}) {
    LightSet set = randomLights(50000, type, 33, true);
    set.lights[7].intensity = Color(0, 0, 0);  // skipped
    set.lights[8].intensity = Color(1e-30f, 0, 0);  // weight rounds to ~0 in float
    TreeBuildOptions o{TreeBuilder::Agglomerative, 5};
    o.exactLimit = 512;  // chunks bottom-up, then the exact top; subtrees over 2^14 lights
    LightForest f = buildLightForest(set, o);
    const LightTree& t = f.trees[0];
    checkTree(set, t);
    std::vector<NodeMoments> ref = serialMoments(set, t);
    ASSERT_EQ(t.nodes.size(), ref.size());
    for (uint32_t i = 0; i < t.nodes.size(); ++i) {
      const NodeMoments got = t.momentsOf(set, i);
      ASSERT_EQ(got.centroid, ref[i].centroid) << i;
      ASSERT_EQ(got.meanAxis, ref[i].meanAxis) << i;
    }
  }
}

// The merge metric is computed four or eight lanes at a time (AVX2, where the CPU has it):
// the same trees bit for bit either way, for every kind of light the metric treats apart.
TEST(Agglomerative, EightLaneMetricGivesTheSameTreesAsFour) {
  if (detail::setMetricLanes(8) != 8) {
    detail::setMetricLanes(0);
    GTEST_SKIP() << "no AVX2 on this CPU";
  }
  for (LightType type : {LightType::Omni, LightType::Oriented, LightType::Directional}) {
    LightSet set = randomLights(30000, type, 41, true);
    TreeBuildOptions o{TreeBuilder::Agglomerative, 5};
    o.exactLimit = 512;  // the bottom-up groups, where the rows are computed
    detail::setMetricLanes(8);
    LightForest eight = buildLightForest(set, o);
    detail::setMetricLanes(4);
    LightForest four = buildLightForest(set, o);
    detail::setMetricLanes(0);
    const LightTree &a = eight.trees[0], &b = four.trees[0];
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.root, b.root);
    for (size_t i = 0; i < a.nodes.size(); ++i)
      ASSERT_EQ(std::memcmp(&a.nodes[i], &b.nodes[i], sizeof(LightNode)), 0) << "node " << i;
  }
}

// Agglomerative clustering must merge the two obvious groups last.
TEST(Agglomerative, MergesNearbyLightsFirst) {
  LightSet set;
  set.groups.push_back(LightGroup{});
  for (int g = 0; g < 2; ++g)
    for (int i = 0; i < 8; ++i) {
      Light l;
      l.position = Vec3(float(g) * 100 + float(i) * 0.1f, 0, 0);
      l.intensity = Color(1);
      set.lights.push_back(l);
    }
  LightForest f = buildLightForest(set);
  const LightTree& t = f.trees[0];
  EXPECT_EQ(leafCount(t, rootLeft(t)), 8u);
  EXPECT_EQ(leafCount(t, rootRight(t)), 8u);
}

// Larger sets are clustered bottom-up in Morton-ordered groups first (Gu et al. 2013): the
// tree must still be a valid hierarchy, the same at any thread count, and about as good as
// the exact greedy one by the merge metric's own measure (box diagonal squared times
// intensity, summed over the inner nodes).
TEST(Agglomerative, BottomUpGroupsGiveAValidDeterministicTree) {
  auto cost = [](const LightTree& t) {
    double c = 0;
    for (const LightNode& n : t.nodes) c += double(luminance(n.intensity)) * double(length2(n.hi - n.lo));
    return c;
  };
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    LightSet set = randomLights(6000, type, 21, true);
    TreeBuildOptions approx{TreeBuilder::Agglomerative, 5};
    approx.exactLimit = 256;  // 6000 lights: chunks reduced bottom-up, then the exact top
    LightForest a = buildLightForest(set, approx);
    checkTree(set, a.trees[0]);
    LightForest b;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      b = buildLightForest(set, approx);
    }
    ASSERT_EQ(a.trees[0].nodes.size(), b.trees[0].nodes.size());
    for (size_t i = 0; i < a.trees[0].nodes.size(); ++i) {
      ASSERT_EQ(a.trees[0].nodes[i].rep, b.trees[0].nodes[i].rep) << i;
      ASSERT_EQ(a.trees[0].nodes[i].a, b.trees[0].nodes[i].a) << i;
      ASSERT_EQ(a.trees[0].nodes[i].b, b.trees[0].nodes[i].b) << i;
    }
    LightForest exact = buildLightForest(set, TreeBuildOptions{TreeBuilder::Agglomerative, 5});
    EXPECT_LT(cost(a.trees[0]), 1.3 * cost(exact.trees[0])) << lightTypeName(type);
  }
}

// The seed split falls at a gap in position rather than at the median.
TEST(SeedBuild, SplitsAtTheLargestGap) {
  LightSet set;
  set.groups.push_back(LightGroup{});
  for (int i = 0; i < 12; ++i) {
    Light l;
    l.position = Vec3(i < 5 ? float(i) : 50 + float(i), 0, 0);
    l.intensity = Color(1);
    set.lights.push_back(l);
  }
  LightForest f = buildLightForest(set, TreeBuildOptions{TreeBuilder::Course, 1});
  const LightTree& t = f.trees[0];
  uint32_t a = leafCount(t, rootLeft(t)), b = leafCount(t, rootRight(t));
  EXPECT_EQ(std::min(a, b), 5u);
  // The seed error of a node of coincident equal lights is zero; of spread lights positive.
  EXPECT_GT(t.course[0].error, 0.0f);
}

TEST(SeedBuild, ErrorIsWeightedMeanDistanceToCentroid) {
  LightSet set;
  set.groups.push_back(LightGroup{});
  for (float x : {0.0f, 2.0f}) {
    Light l;
    l.position = Vec3(x, 0, 0);
    l.intensity = Color(1);
    set.lights.push_back(l);
  }
  LightForest f = buildLightForest(set, TreeBuildOptions{TreeBuilder::Course, 1});
  EXPECT_FLOAT_EQ(f.trees[0].course[0].error, 1.0f);  // same colour: no spread factor
  EXPECT_EQ(f.trees[0].course[0].position, Vec3(1, 0, 0));
}

// Issue 23: lights of huge but finite power (2e38: the sums overflow a float) used to make the
// agglomerative metric inf or NaN, and the build never finished. It must finish at once and
// give a valid tree whose node intensities stay finite.
TEST(TreeBuild, HugeIntensitiesBuildQuicklyAndStayFinite) {
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    for (size_t exactLimit : {size_t(0), size_t(8192), size_t(64)}) {
      LightSet set = randomLights(300, type, 7);
      for (size_t i = 0; i < set.lights.size(); ++i) {
        set.lights[i].intensity = Color(2e38f, 2e38f, i % 3 == 0 ? 3e38f : 0.0f);
        if (i % 2) set.lights[i].position = set.lights[i - 1].position;  // co-located pairs
      }
      auto done = std::make_shared<std::promise<LightForest>>();
      std::future<LightForest> result = done->get_future();
      TreeBuildOptions o;
      o.exactLimit = exactLimit == 0 ? 8192 : exactLimit;
      if (exactLimit == 0) o.builder = TreeBuilder::Course;  // the other builder too
      std::thread([done, set, o] { done->set_value(buildLightForest(set, o)); }).detach();
      if (result.wait_for(std::chrono::seconds(1)) != std::future_status::ready) {
        std::fprintf(stderr, "the tree build over lights of 2e38 did not finish within a second\n");
        std::_Exit(1);  // the builder thread cannot be stopped
      }
      LightForest f = result.get();
      ASSERT_EQ(f.trees.size(), 1u);
      const LightTree& t = f.trees[0];
      EXPECT_EQ(t.nodes.size(), set.lights.size() - 1);
      std::set<uint32_t> leaves;
      for (NodeRef r : t.preorderNodes()) {
        const LightNode n = t.node(set, r);
        EXPECT_TRUE(isFinite(n.intensity));
        EXPECT_TRUE(isFinite(n.lo) && isFinite(n.hi));
        if (isLeafRef(r)) {
          EXPECT_TRUE(leaves.insert(n.rep).second);
        }
      }
      EXPECT_EQ(leaves.size(), set.lights.size());
    }
  }
}

// The metric itself does not overflow for huge intensities or extents.
TEST(Agglomerative, ClusterMetricIsFiniteForHugeValues) {
  float m = clusterMetric(3e38f, Vec3(-1e15f), Vec3(1e15f), -1, 1e15f);
  EXPECT_TRUE(std::isfinite(m));
  EXPECT_GT(m, 0);
  EXPECT_EQ(clusterMetric(3e38f, Vec3(1), Vec3(1), 1, 1), 0);
}

TEST(Nodes, AreCompact) { EXPECT_LE(sizeof(LightNode), 64u); }

// ---- precision over millions of lights (issue 21: 8.1M VPLs) ----

// A bright light that absorbs ten million dim ones, one merge at a time: the longest chain
// a tree can have. All sit at one point with one normal, so the cluster's light at any
// receiver is exactly (B + N t) f, f one light's contribution per unit intensity. A float
// sum along the chain never grows: each t is below half an ulp of it (it came out 1
// instead of 1.3 here); summed in double, the node's intensity, its estimate and its bounds
// hold to float rounding.
TEST(Precision, ChainOfTenMillionMergesKeepsTheClusterIntensity) {
  constexpr uint32_t kDim = 10'000'000;
  const Color bright(1.0f, 0.5f, 0.25f), dim = bright * 3e-8f;
  Light l;
  l.type = LightType::Oriented;
  l.position = Vec3(0.5f, 3, -0.25f);
  l.direction = Vec3(0, -1, 0);
  l.intensity = bright;
  detail::Cluster c = detail::leafCluster(l, 0);
  l.intensity = dim;
  for (uint32_t i = 1; i <= kDim; ++i)
    c = detail::mergeClusters(c, detail::leafCluster(l, i), int32_t(2 * i), int32_t(2 * i + 1), true, 7);
  LightNode node{};
  detail::setNodeFromCluster(node, c);
  for (int k = 0; k < 3; ++k) {
    const double want = double(bright[k]) + double(kDim) * double(dim[k]);
    EXPECT_NEAR(node.intensity[k], want, 1e-6 * want) << "channel " << k;
  }

  LightGroup g;
  ShadingPoint sp = test_lights::point(Vec3(0, 0, 0));
  Color unit;
  Vec3 wi;
  float dist;
  ASSERT_TRUE(lightContribution(l, g, sp, unit, wi, dist));
  const double total = double(luminance(bright)) + double(kDim) * double(luminance(dim));
  const double exact = double(luminance(unit)) * total;  // M G is one colour: luminance factors only
  Color cm = unit * (bright + dim * float(kDim));        // closed form, per channel
  EXPECT_NEAR(luminance(unit * node.intensity), luminance(cm), 1e-6 * exact) << "estimate";
  Color lower;
  Color upper = clusterBounds(node, LightType::Oriented, g, sp, BoundFrames(sp), &lower);
  // The bounds carry a few 1e-4 of slack against rounding; the float sum lost 23%.
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(lower[k], cm[k] * (1 + 1e-6f)) << "channel " << k;
    EXPECT_GE(upper[k], cm[k] * (1 - 1e-6f)) << "channel " << k;
    EXPECT_NEAR(upper[k], cm[k], 5e-4f * cm[k]) << "channel " << k;
    EXPECT_NEAR(lower[k], cm[k], 5e-4f * cm[k]) << "channel " << k;
  }
}

// Node moments of a caterpillar tree (each inner node: one leaf and the rest) over a
// million lights at x = i / N, all alike: every node's centroid is the mean of its suffix,
// (i0 + N - 1) / (2N), in closed form. Means of the children's float means lose ~1e-7 per
// level, and here there are a million levels.
TEST(Precision, MomentsOfAMillionLevelChainAreExact) {
  constexpr uint32_t kN = 1'000'000;
  LightSet s;
  s.groups.push_back(LightGroup{});
  s.lights.resize(kN);
  for (uint32_t i = 0; i < kN; ++i) {
    s.lights[i].type = LightType::Omni;
    s.lights[i].position = Vec3(float(i) / float(kN), 1, 0);
    s.lights[i].direction = Vec3(0, 0, 1);
    s.lights[i].intensity = Color(0.3f);
  }
  // Inner node j (slot j, j < N-1): its left child is light j's leaf, its right child
  // the rest (slot j + 1, or light N-1's leaf).
  LightTree t;
  t.type = LightType::Omni;
  t.lightTotal = kN;
  t.root = 0;
  t.nodes.resize(size_t(kN) - 1);
  for (uint32_t j = kN - 1; j-- > 0;) {
    LightNode& n = t.nodes[j];
    n = LightNode{};
    n.lo = Vec3(float(j) / float(kN), 1, 0);
    n.hi = Vec3(float(kN - 1) / float(kN), 1, 0);
    n.intensity = Color(float(0.3 * double(kN - j)));
    n.rep = j;
    const bool lastPair = j + 2 == kN;
    n.setChildren(true, j, lastPair, kN - 1, kN - j);
  }
  computeMoments(s, t);
  for (uint32_t j : {0u, 1u, 1000u, kN / 2, kN - 10}) {
    const NodeMoments m = t.momentsOf(s, j);
    const double want = (double(j) + double(kN - 1)) / (2.0 * kN);
    EXPECT_NEAR(m.centroid.x, want, 1e-6 * want) << "node of the suffix from light " << j;
    EXPECT_EQ(t.lightCount(j), kN - j);
  }
}

}  // namespace
}  // namespace lc::lightcuts
