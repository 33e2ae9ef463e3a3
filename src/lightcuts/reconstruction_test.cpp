#include "lightcuts/reconstruction.h"

#include <gtest/gtest.h>

#include <functional>

#include "lightcuts/evaluator.h"
#include "lightcuts/test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::cloud;
using test_lights::point;

// Visibility from a function of the direction, counting the rays it answers.
struct CountingVisibility : Visibility {
  std::function<Color(const Vec3&)> f;
  int rays = 0;
  explicit CountingVisibility(std::function<Color(const Vec3&)> fn) : f(std::move(fn)) {}
  Color operator()(const Vec3& wi, float) override {
    ++rays;
    return f(wi);
  }
};

Color open(const Vec3&) { return Color(1); }
Color halfBlocked(const Vec3& wi) { return wi.x < 0 ? Color(0) : Color(1); }
Color allBlocked(const Vec3&) { return Color(0); }

uint32_t subtreeSize(const LightTree& t, uint32_t i) {
  const LightNode& n = t.nodes[i];
  return n.isLeaf() ? 1 : 1 + subtreeSize(t, n.left) + subtreeSize(t, n.left + 1);
}

struct Fixture {
  LightSet lights = cloud(3000, LightType::Omni, 11);
  LightForest forest = buildLightForest(lights);
  std::unique_ptr<LightEvaluator> lc = makeLightcuts(lights, forest, CutOptions{});

  CutRecord record(const ShadingPoint& sp, Color (*vis)(const Vec3&), EvalResult* result = nullptr) {
    CutRecord r;
    CountingVisibility v(vis);
    EvalStats st;
    EvalResult e = lc->evaluateRecorded(sp, v, st, r);
    if (result) *result = e;
    return r;
  }
};

TEST(Reconstruction, PreorderMakesEverySubtreeAContiguousRange) {
  Fixture f;
  ASSERT_EQ(f.forest.trees.size(), 1u);
  const LightTree& t = f.forest.trees[0];
  ASSERT_EQ(t.preorder.size(), t.nodes.size());
  std::vector<int> seen(t.nodes.size(), 0);
  for (uint32_t i = 0; i < t.nodes.size(); ++i) {
    ASSERT_LT(t.preorder[i], t.nodes.size());
    ++seen[t.preorder[i]];
    const LightNode& n = t.nodes[i];
    if (n.isLeaf()) continue;
    EXPECT_EQ(t.preorder[n.left], t.preorder[i] + 1);
    EXPECT_EQ(t.preorder[n.left + 1], t.preorder[i] + 1 + subtreeSize(t, n.left));
  }
  for (int c : seen) EXPECT_EQ(c, 1);
}

TEST(Reconstruction, RecordedCutIsThePartitionTheLightcutUsed) {
  Fixture f;
  EvalResult full;
  CutRecord r = f.record(point(Vec3(0.2f, 0, 0.1f)), open, &full);
  ASSERT_TRUE(r.valid);
  ASSERT_EQ(r.treeBegin.size(), 2u);
  EXPECT_EQ(r.entries.size(), full.cutSize);
  for (size_t i = 1; i < r.entries.size(); ++i) EXPECT_LT(r.entries[i - 1] >> 2, r.entries[i] >> 2);
  // Disjoint subtrees (each starts past the previous one's range) covering every leaf.
  const LightTree& t = f.forest.trees[0];
  std::vector<uint32_t> byPre(t.nodes.size());
  for (uint32_t i = 0; i < t.nodes.size(); ++i) byPre[t.preorder[i]] = i;
  uint32_t next = 0, leaves = 0;
  for (uint32_t e : r.entries) {
    uint32_t node = byPre[e >> 2];
    EXPECT_GE(e >> 2, next) << "overlapping subtrees";
    next = (e >> 2) + subtreeSize(t, node);
    leaves += test_lights::leafCount(t, node);
    EXPECT_EQ(CutVisibility(e & 3), CutVisibility::Visible);
  }
  EXPECT_EQ(leaves, f.lights.lights.size());
}

TEST(Reconstruction, ASampleRebuildsItsOwnLightcutWithoutShadowRays) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 0, 0.1f));
  EvalResult full;
  CutRecord r = f.record(sp, halfBlocked, &full);
  const CutRecord* four[4] = {&r, &r, &r, &r};
  MergedCut m;
  f.lc->mergeSamples(four, 4, m);
  EXPECT_EQ(m.nodes.size() + m.occluded, full.cutSize);
  EXPECT_GT(m.occluded, 0u);
  CountingVisibility v(halfBlocked);
  EvalStats st;
  EvalResult e = f.lc->reconstruct(sp, v, st, m);
  EXPECT_EQ(v.rays, 0);  // every sample agrees on every node
  EXPECT_EQ(e.cutSize, full.cutSize);
  EXPECT_NEAR(luminance(e.radiance), luminance(full.radiance), 1e-4f * luminance(full.radiance));
  EXPECT_EQ(st.reconstructedPoints, 1u);
}

TEST(Reconstruction, SamplesThatDisagreeSendTheRayAndAgreeingOnesDoNot) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 0, 0.1f));
  CutRecord a = f.record(sp, halfBlocked), b = f.record(sp, open);
  const CutRecord* two[2] = {&a, &b};
  MergedCut m;
  f.lc->mergeSamples(two, 2, m);
  size_t needRay = 0;
  for (const MergedCut::Node& n : m.nodes) needRay += n.needsRay;
  EXPECT_GT(needRay, 0u);
  EXPECT_LT(needRay, m.nodes.size());
  CountingVisibility v(halfBlocked);
  EvalStats st;
  f.lc->reconstruct(sp, v, st, m);
  EXPECT_EQ(size_t(v.rays), needRay);
  EXPECT_EQ(st.shadowRays, needRay);

  // Samples that saw nothing: the point is dark, at no cost.
  CutRecord c = f.record(sp, allBlocked);
  const CutRecord* one[1] = {&c};
  f.lc->mergeSamples(one, 1, m);
  EXPECT_TRUE(m.nodes.empty());
  CountingVisibility o(open);
  EvalResult e = f.lc->reconstruct(sp, o, st, m);
  EXPECT_EQ(o.rays, 0);
  EXPECT_EQ(luminance(e.radiance), 0.0f);
}

TEST(Reconstruction, MergedCutIsAtLeastAsFineAsEverySample) {
  Fixture f;
  // Points spread so that their cuts refine different parts of the tree.
  const Vec3 ps[4] = {Vec3(-1.5f, 1.5f, -1.5f), Vec3(1.5f, 1.5f, -1.5f), Vec3(-1.5f, 0, 1.5f), Vec3(1.5f, 0, 1.5f)};
  CutRecord r[4];
  uint32_t largest = 0;
  for (int i = 0; i < 4; ++i) {
    EvalResult e;
    r[i] = f.record(point(ps[i]), open, &e);
    largest = std::max(largest, e.cutSize);
  }
  const CutRecord* four[4] = {&r[0], &r[1], &r[2], &r[3]};
  MergedCut m;
  f.lc->mergeSamples(four, 4, m);
  EXPECT_GT(uint32_t(m.nodes.size()), largest);
  // Still a partition of the lights: the intensities add up to the root's.
  Color sum(0);
  for (const MergedCut::Node& n : m.nodes) sum += n.intensity;
  Color root = f.forest.trees[0].nodes[0].intensity;
  EXPECT_NEAR(sum.x, root.x, 1e-3f * root.x);
  EXPECT_NEAR(sum.z, root.z, 1e-3f * root.z);
  // Evaluated at each sample, the merged cut keeps the lightcut's accuracy.
  auto brute = makeBruteForce(f.lights);
  for (int i = 0; i < 4; ++i) {
    ShadingPoint sp = point(ps[i]);
    CountingVisibility v(open);
    EvalStats st;
    float exact = luminance(brute->evaluate(sp, v, st).radiance);
    float recErr = std::fabs(luminance(f.lc->reconstruct(sp, v, st, m).radiance) - exact);
    EXPECT_LT(recErr, 0.02f * exact) << "sample " << i;
  }
}

}  // namespace
}  // namespace lc::lightcuts
