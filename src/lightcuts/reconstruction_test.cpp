#include "lightcuts/reconstruction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include <functional>

#include "lightcuts/evaluator.h"
#include "lightcuts/merged_batch.h"
#include "test_lights.h"

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

uint32_t subtreeSize(const LightTree& t, NodeRef i) {
  if (isLeafRef(i)) return 1;
  const LightNode& n = t.nodes[i];
  return 1 + subtreeSize(t, n.left(i)) + subtreeSize(t, n.right(i));
}

// The position of node r in LightTree::preorderNodes.
uint32_t preorderOf(const LightTree& t, NodeRef r) {
  const std::vector<NodeRef> all = t.preorderNodes();
  return uint32_t(std::find(all.begin(), all.end(), r) - all.begin());
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
  // The merged cut of two records.
  MergedCut merged(const CutRecord& a, const CutRecord& b) {
    const CutRecord* two[2] = {&a, &b};
    MergedCut m;
    lc->mergeSamples(two, 2, m);
    return m;
  }
  // The merged cut of four samples that agree on everything (one record four times).
  MergedCut agreeing(const CutRecord& r) {
    const CutRecord* four[4] = {&r, &r, &r, &r};
    MergedCut m;
    lc->mergeSamples(four, 4, m);
    return m;
  }
};

TEST(Reconstruction, PreorderMakesEverySubtreeAContiguousRange) {
  Fixture f;
  ASSERT_EQ(f.forest.trees.size(), 1u);
  const LightTree& t = f.forest.trees[0];
  // The walks carry a node's preorder position down (LightNode::leftPre, rightPre): they
  // must agree with a plain depth-first walk's, and each subtree spans 2 count - 1.
  const std::vector<NodeRef> all = t.preorderNodes();
  ASSERT_EQ(all.size(), 2 * size_t(t.lightTotal) - 1);
  std::set<NodeRef> seen(all.begin(), all.end());
  EXPECT_EQ(seen.size(), all.size());
  for (uint32_t p = 0; p < all.size(); ++p) {
    const NodeRef r = all[p];
    EXPECT_EQ(subtreeSize(t, r), 2 * t.lightCount(r) - 1);
    if (isLeafRef(r)) continue;
    const LightNode& n = t.nodes[r];
    ASSERT_LT(n.rightPre(p), all.size());
    EXPECT_EQ(all[LightNode::leftPre(p)], n.left(r));
    EXPECT_EQ(all[n.rightPre(p)], n.right(r));
    EXPECT_EQ(n.rightPre(p), p + 1 + subtreeSize(t, n.left(r)));
  }
}

TEST(Reconstruction, RecordedCutIsThePartitionTheLightcutUsed) {
  Fixture f;
  EvalResult full;
  CutRecord r = f.record(point(Vec3(0.2f, 0, 0.1f)), open, &full);
  ASSERT_TRUE(r.valid);
  ASSERT_EQ(r.treeBegin.size(), 2u);
  EXPECT_EQ(r.entries.size(), full.cutSize);
  for (size_t i = 1; i < r.entries.size(); ++i) EXPECT_LT(CutRecord::preorderOf(r.entries[i - 1]), CutRecord::preorderOf(r.entries[i]));
  // Disjoint subtrees (each starts past the previous one's range) covering every leaf.
  const LightTree& t = f.forest.trees[0];
  const std::vector<NodeRef> byPre = t.preorderNodes();
  uint32_t next = 0, leaves = 0;
  ASSERT_EQ(r.nodes.size(), r.entries.size());
  for (size_t i = 0; i < r.entries.size(); ++i) {
    const uint32_t e = r.entries[i];
    NodeRef node = byPre[CutRecord::preorderOf(e)];
    EXPECT_EQ(r.nodes[i], node) << "the entry's node";
    EXPECT_GE(CutRecord::preorderOf(e), next) << "overlapping subtrees";
    next = CutRecord::preorderOf(e) + subtreeSize(t, node);
    leaves += test_lights::leafCount(t, node);
    EXPECT_EQ(CutRecord::visibilityOf(e), CutVisibility::Visible);
  }
  EXPECT_EQ(leaves, f.lights.lights.size());
}

// Large cuts are sorted by another path (a radix sort from 256 entries up): the record of
// a cut of thousands of nodes over two trees is still each tree's partition, in preorder.
TEST(Reconstruction, LargeRecordedCutIsInPreorderPerTree) {
  LightSet lights = cloud(4000, LightType::Omni, 5);
  LightSet oriented = cloud(4000, LightType::Oriented, 6);
  for (const Light& l : oriented.lights) lights.lights.push_back(l);
  LightForest forest = buildLightForest(lights);
  ASSERT_EQ(forest.trees.size(), 2u);
  CutOptions fine;
  fine.errorRatio = 0.0005f;
  fine.maxCut = 100000;
  std::unique_ptr<LightEvaluator> lc = makeLightcuts(lights, forest, fine);
  CountingVisibility v(halfBlocked);
  EvalStats st;
  CutRecord r;
  EvalResult e = lc->evaluateRecorded(point(Vec3(0.2f, 0, 0.1f)), v, st, r);
  ASSERT_TRUE(r.valid);
  ASSERT_GE(r.entries.size(), 1000u);
  EXPECT_EQ(r.entries.size(), e.cutSize);
  ASSERT_EQ(r.treeBegin.size(), 3u);
  EXPECT_EQ(r.treeBegin[0], 0u);
  EXPECT_EQ(r.treeBegin[2], r.entries.size());
  size_t leavesTotal = 0;
  for (uint32_t t = 0; t < 2; ++t) {
    const LightTree& tree = forest.trees[t];
    const std::vector<NodeRef> byPre = tree.preorderNodes();
    uint32_t next = 0, leaves = 0;
    for (uint32_t k = r.treeBegin[t]; k < r.treeBegin[t + 1]; ++k) {
      const uint32_t pre = CutRecord::preorderOf(r.entries[k]);
      ASSERT_LT(pre, byPre.size());
      EXPECT_GE(pre, next) << "tree " << t << ": out of order or overlapping at entry " << k;
      next = pre + subtreeSize(tree, byPre[pre]);
      leaves += test_lights::leafCount(tree, byPre[pre]);
    }
    EXPECT_EQ(leaves, tree.lightCount(tree.root)) << "tree " << t;
    leavesTotal += leaves;
  }
  EXPECT_EQ(leavesTotal, lights.lights.size());
}

TEST(Reconstruction, ASampleRebuildsItsOwnLightcutWithoutShadowRays) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 0, 0.1f));
  EvalResult full;
  MergedCut m = f.agreeing(f.record(sp, halfBlocked, &full));
  EXPECT_EQ(m.nodes.size() + m.occluded, full.cutSize);
  EXPECT_GT(m.occluded, 0u);
  CountingVisibility v(halfBlocked);
  EvalStats st;
  EvalResult e = f.lc->reconstruct(sp, v, st, m);
  // Every sample agrees on every node: the only rays are the group probes, of the visible
  // nodes and of the hidden ones (none fails).
  EXPECT_EQ(uint64_t(v.rays), st.groupProbes);
  EXPECT_EQ(st.failedGroupProbes, 0u);
  EXPECT_LE(st.groupProbes, m.groupProbe.size() + m.hiddenProbe.size());
  EXPECT_EQ(e.cutSize, full.cutSize);
  EXPECT_NEAR(luminance(e.radiance), luminance(full.radiance), 1e-4f * luminance(full.radiance));
  EXPECT_EQ(st.reconstructedPoints, 1u);
}

// A group of borrowed-visible nodes that the point does not see though every sample did (a
// shadow thinner than the sample spacing) is caught by its probe when it holds more than
// the probe share of the point's light, and only then; the evaluator's share is half its
// error ratio (groupProbeShare), so an unprobed hidden group costs at most that much.
TEST(Reconstruction, AHiddenGroupIsCaughtWhenItHoldsMoreThanTheProbeShare) {
  Fixture f;
  // Just under the cloud, where one group holds a few per cent of the light.
  ShadingPoint sp = point(Vec3(0.2f, 2, 0.1f));
  MergedCut m = f.agreeing(f.record(sp, open));
  ASSERT_GE(m.groupProbe.size(), 2u);
  CountingVisibility all(open);
  EvalStats st;
  const float total = luminance(evaluateMergedCut(f.lights, m, sp, all, st, 0.0f, 0.0f).radiance);
  // The dimmest group with some light: the one a thin shadow hides.
  constexpr size_t kBlocks = MergedCut::kGroupSize / 4;
  size_t hiddenGroup = 0;
  float groupLight = kInf;
  for (size_t g = 0; g < m.groupProbe.size(); ++g) {
    const float l = luminance(evaluateBatch(m.batch, sp, g * kBlocks, (g + 1) * kBlocks));
    if (l > 0 && l < groupLight) groupLight = l, hiddenGroup = g;
  }
  const float share = groupLight / total;
  // Between half the default error ratio and the 4% the probe once needed.
  ASSERT_GT(share, 0.01f);
  ASSERT_LT(share, 0.04f);
  std::vector<Vec3> hiddenDirs;
  for (size_t i = hiddenGroup * MergedCut::kGroupSize;
       i < std::min(m.batchNodes.size(), (hiddenGroup + 1) * MergedCut::kGroupSize); ++i)
    hiddenDirs.push_back(normalize(f.lights.lights[m.nodes[m.batchNodes[i]].rep].position - sp.p));
  auto shadowed = [&](const Vec3& wi) {
    for (const Vec3& d : hiddenDirs)
      if (dot(wi, d) > 0.99999f) return Color(0);
    return Color(1);
  };
  auto evaluate = [&](float probeShare, EvalStats& s, float refuteShare = 1.0f) {
    CountingVisibility v(shadowed);
    return luminance(evaluateMergedCut(f.lights, m, sp, v, s, probeShare, refuteShare).radiance);
  };
  EvalStats caught, missed;
  EXPECT_NEAR(evaluate(0.99f * share, caught), total - groupLight, 1e-3f * total);
  EXPECT_GE(caught.failedGroupProbes, 1u);
  EXPECT_EQ(caught.refutingGroupProbes, 0u);  // the group holds less than the refuting share
  EXPECT_NEAR(evaluate(1.01f * share, missed), total, 1e-4f * total);
  EXPECT_EQ(missed.failedGroupProbes, 0u);
  // The failed probe refutes the samples when its group holds more than the refuting
  // share of the point's light (measured before the group was taken out), and only then.
  EvalStats refuted, notRefuted;
  evaluate(0.5f * share, refuted, 0.99f * share);
  EXPECT_GE(refuted.refutingGroupProbes, 1u);
  evaluate(0.5f * share, notRefuted, 1.01f * share);
  EXPECT_GE(notRefuted.failedGroupProbes, 1u);
  EXPECT_EQ(notRefuted.refutingGroupProbes, 0u);
  EXPECT_EQ(refutingProbeShare(0.02f), 0.02f);
  // Through the evaluator, at its error ratio: caught when the group holds over half of it.
  EXPECT_EQ(groupProbeShare(0.02f), 0.01f);
  CountingVisibility v(shadowed);
  EvalStats s;
  const float viaCut = luminance(f.lc->reconstruct(sp, v, s, m).radiance);
  EXPECT_NEAR(viaCut, total - groupLight, 1e-3f * total);
}

// A group of nodes that every sample found occluded but the point sees (a gap between
// occluders thinner than the sample spacing) is caught by its probe when it would hold over
// the probe share of the point's light; unprobed, its light is missing.
TEST(Reconstruction, AGroupTheSamplesFoundHiddenButThePointSeesIsCaught) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 2, 0.1f));
  MergedCut m = f.agreeing(f.record(sp, halfBlocked));
  ASSERT_GE(m.hiddenProbe.size(), 2u);
  EXPECT_EQ(m.hidden.size(), size_t(m.occluded));  // every node here is an omni light's
  // The point sees the first hidden group's lights besides what the samples saw.
  std::vector<Vec3> gap;
  double gapLight = 0;
  for (size_t i = 0; i < std::min<size_t>(m.hidden.size(), MergedCut::kGroupSize); ++i) {
    const Light& l = f.lights.lights[m.hidden[i].rep];
    Color mg;
    Vec3 wi;
    float dist;
    if (!lightContribution(l, f.lights.groups[l.group], sp, mg, wi, dist)) continue;
    gap.push_back(wi);
    gapLight += luminance(mg * m.hidden[i].intensity);
  }
  ASSERT_GT(gapLight, 0.0);
  auto seen = [&](const Vec3& wi) {
    for (const Vec3& d : gap)
      if (dot(wi, d) > 0.99999f) return Color(1);
    return halfBlocked(wi);
  };
  auto evaluate = [&](float probeShare, EvalStats& s) {
    CountingVisibility v(seen);
    return luminance(evaluateMergedCut(f.lights, m, sp, v, s, probeShare, 0.0f).radiance);
  };
  EvalStats missed, caught;
  const float without = evaluate(1e30f, missed);  // no group probed
  EXPECT_EQ(missed.groupProbes, 0u);
  EXPECT_NEAR(evaluate(0.0f, caught), without + gapLight, 1e-3 * (without + gapLight));
  EXPECT_GE(caught.failedGroupProbes, 1u);
  EXPECT_GE(caught.refutingGroupProbes, 1u);  // any share refutes at a refuting share of 0
}

TEST(Reconstruction, SamplesThatDisagreeSendTheRayAndAgreeingOnesDoNot) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 0, 0.1f));
  CutRecord a = f.record(sp, halfBlocked), b = f.record(sp, open);
  MergedCut m = f.merged(a, b);
  size_t needRay = 0;
  for (const MergedCut::Node& n : m.nodes) needRay += n.needsRay;
  EXPECT_GT(needRay, 0u);
  EXPECT_LT(needRay, m.nodes.size());
  CountingVisibility v(halfBlocked);
  EvalStats st;
  f.lc->reconstruct(sp, v, st, m);
  EXPECT_EQ(size_t(v.rays), needRay + st.groupProbes);
  EXPECT_EQ(st.shadowRays, needRay + st.groupProbes);

  // Samples that saw nothing: a point that sees nothing either is dark, for at most one
  // probe ray per group of hidden nodes.
  CutRecord c = f.record(sp, allBlocked);
  const CutRecord* one[1] = {&c};
  f.lc->mergeSamples(one, 1, m);
  EXPECT_TRUE(m.nodes.empty());
  CountingVisibility o(allBlocked);
  EvalResult e = f.lc->reconstruct(sp, o, st, m);
  EXPECT_LE(size_t(o.rays), m.hiddenProbe.size());
  EXPECT_EQ(luminance(e.radiance), 0.0f);
}

// The nodes two samples disagree about are those behind the half-space wall; their share
// of the diffuse light is about the share of the lights behind it (measured light by
// light), and nothing where the samples agree.
TEST(Reconstruction, DisagreementShareIsTheLightOfTheNodesInDispute) {
  Fixture f;
  ShadingPoint sp = point(Vec3(0.2f, 0, 0.1f));
  CutRecord a = f.record(sp, halfBlocked), b = f.record(sp, open);
  MergedCut m = f.merged(a, b);
  auto disputed = [](const MergedCut& c) {
    uint32_t k = 0;
    for (const MergedCut::Node& n : c.nodes) k += n.disagree;
    return k;
  };
  EXPECT_GT(disputed(m), 0u);
  EXPECT_LT(disputed(m), m.nodes.size());
  double hidden = 0, all = 0;
  ShadingPoint diffuse = sp;
  diffuse.kd = Color(1);
  diffuse.ks = Color(0);
  for (const Light& l : f.lights.lights) {
    Color mg;
    Vec3 wi;
    float dist;
    if (!lightContribution(l, f.lights.groups[l.group], diffuse, mg, wi, dist)) continue;
    double c = luminance(mg * l.intensity);
    all += c;
    if (halfBlocked(wi).x == 0) hidden += c;
  }
  ASSERT_GT(hidden, 0.1 * all);
  EXPECT_NEAR(disagreementShare(f.lights, m, sp.p, sp.n), hidden / all, 0.05);

  m = f.merged(a, a);
  EXPECT_EQ(disputed(m), 0u);
  EXPECT_EQ(disagreementShare(f.lights, m, sp.p, sp.n), 0.0f);
}

TEST(Reconstruction, MergedCutIsAPartitionAccurateAtEverySample) {
  Fixture f;
  // Points a cell apart (the first-order factors they lend each other hold nearby), spread
  // enough that their cuts refine different parts of the tree.
  const Vec3 ps[4] = {Vec3(-0.2f, 0, -0.2f), Vec3(0.2f, 0, -0.2f), Vec3(-0.2f, 0.3f, 0.2f), Vec3(0.2f, 0.3f, 0.2f)};
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
  // Finer than some samples' cuts where they differ (near these points the lights' 1/d^2
  // clamp makes clusters non-smooth), coarser where all are smooth and visible.
  EXPECT_GT(uint32_t(m.nodes.size()), largest / 2);
  // Still a partition of the lights: the intensities add up to the root's.
  Color sum(0);
  for (const MergedCut::Node& n : m.nodes) sum += n.intensity;
  Color root = f.forest.trees[0].nodes[f.forest.trees[0].root].intensity;
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

// A recorded cut carries its prefix count of rough entries (CutRecord::rough), and a merge
// of records without it (hand-made ones) counts them itself, to the same merged cut.
TEST(Reconstruction, RecordedRoughCountsMatchAndMergeTheSameWithout) {
  Fixture f;
  const Vec3 ps[4] = {Vec3(-0.2f, 0, -0.2f), Vec3(0.2f, 0, -0.2f), Vec3(-0.2f, 0.3f, 0.2f), Vec3(0.2f, 0.3f, 0.2f)};
  CutRecord r[4], bare[4];
  bool someRough = false, someSmooth = false;
  for (int i = 0; i < 4; ++i) {
    r[i] = f.record(point(ps[i]), halfBlocked);
    ASSERT_EQ(r[i].rough.size(), r[i].entries.size() + 1);
    uint32_t n = 0;
    for (size_t k = 0; k < r[i].entries.size(); ++k) {
      EXPECT_EQ(r[i].rough[k], n);
      const bool smooth = CutRecord::visibilityOf(r[i].entries[k]) == CutVisibility::Visible &&
                          CutRecord::firstOrderOf(r[i].entries[k]);
      n += !smooth;
      (smooth ? someSmooth : someRough) = true;
    }
    EXPECT_EQ(r[i].rough.back(), n);
    bare[i] = r[i];
    bare[i].rough.clear();
  }
  EXPECT_TRUE(someRough && someSmooth);  // both kinds, so the counts matter
  const CutRecord* withCounts[4] = {&r[0], &r[1], &r[2], &r[3]};
  const CutRecord* without[4] = {&bare[0], &bare[1], &bare[2], &bare[3]};
  for (int count = 2; count <= 4; ++count) {
    MergedCut a, b;
    f.lc->mergeSamples(withCounts, count, a);
    f.lc->mergeSamples(without, count, b);
    ASSERT_EQ(a.nodes.size(), b.nodes.size()) << count;
    for (size_t k = 0; k < a.nodes.size(); ++k) {
      EXPECT_EQ(a.nodes[k].node, b.nodes[k].node);
      EXPECT_EQ(a.nodes[k].needsRay, b.nodes[k].needsRay);
      EXPECT_EQ(a.nodes[k].factor, b.nodes[k].factor);
    }
    EXPECT_EQ(a.occluded, b.occluded);
  }
}

}  // namespace
}  // namespace lc::lightcuts

namespace lc::lightcuts {
namespace {

using test_lights::cloud;

// Hand-made records over one tree: sample A kept the root's two children, sample B the
// root itself.
TEST(Reconstruction, AgreeingSmoothVisibleSamplesKeepTheCoarserCut) {
  LightSet lights = cloud(64, LightType::Omni, 3);
  LightForest forest = buildLightForest(lights);
  auto lc = makeLightcuts(lights, forest, CutOptions{});
  const LightTree& t = forest.trees[0];
  const NodeRef l = t.nodes[0].left(0), r = t.nodes[0].right(0);
  const uint32_t preL = preorderOf(t, l), preR = preorderOf(t, r);
  auto rec = [&](std::vector<uint32_t> entries, std::vector<float> factors) {
    CutRecord c;
    c.valid = true;
    c.entries = std::move(entries);
    c.factor = std::move(factors);
    for (uint32_t e : c.entries) c.nodes.push_back(t.preorderNodes()[CutRecord::preorderOf(e)]);
    c.treeBegin = {0, uint32_t(c.entries.size())};
    return c;
  };
  const CutVisibility V = CutVisibility::Visible, O = CutVisibility::Occluded;
  CutRecord b = rec({CutRecord::pack(0, V, true)}, {0.9f});
  MergedCut m;

  // Both visible with first-order estimates: the root alone, without a ray, with the
  // first-order factor of the sample that kept it.
  CutRecord a = rec({CutRecord::pack(preL, V, true), CutRecord::pack(preR, V, true)}, {1.1f, 1.2f});
  const CutRecord* ab[2] = {&a, &b};
  lc->mergeSamples(ab, 2, m);
  ASSERT_EQ(m.nodes.size(), 1u);
  EXPECT_EQ(m.nodes[0].node, 0u);
  EXPECT_FLOAT_EQ(m.nodes[0].factor, 0.9f);
  EXPECT_FALSE(m.nodes[0].needsRay);

  // A saw part of it hidden: A's finer cut, with a ray where the samples disagree; the
  // visible child keeps A's factor (B holds only its parent).
  CutRecord a2 = rec({CutRecord::pack(preL, O, false), CutRecord::pack(preR, V, true)}, {1, 1.2f});
  const CutRecord* a2b[2] = {&a2, &b};
  lc->mergeSamples(a2b, 2, m);
  ASSERT_EQ(m.nodes.size(), 2u);
  EXPECT_EQ(m.nodes[0].node, l);
  EXPECT_TRUE(m.nodes[0].needsRay);
  EXPECT_FLOAT_EQ(m.nodes[0].factor, 1.0f);
  EXPECT_EQ(m.nodes[1].node, r);
  EXPECT_FALSE(m.nodes[1].needsRay);
  EXPECT_FLOAT_EQ(m.nodes[1].factor, 1.2f);

  // B's root estimate was not first-order (not smooth there): the finer cut again, with
  // no first-order factor.
  CutRecord b2 = rec({CutRecord::pack(0, V, false)}, {1});
  const CutRecord* ab2[2] = {&a, &b2};
  lc->mergeSamples(ab2, 2, m);
  ASSERT_EQ(m.nodes.size(), 2u);
  EXPECT_FLOAT_EQ(m.nodes[1].factor, 1.0f);
}

// Each sample refines a different half: the merged cut is the finer entry on each side,
// the coarser sample's visibility lent to the finer one's nodes under it.
TEST(Reconstruction, MergedCutTakesTheFinerEntryOnEachSide) {
  LightSet lights = cloud(64, LightType::Omni, 3);
  LightForest forest = buildLightForest(lights);
  auto lc = makeLightcuts(lights, forest, CutOptions{});
  const LightTree& t = forest.trees[0];
  const std::vector<NodeRef> byPre = t.preorderNodes();
  const NodeRef l = t.nodes[0].left(0), r = t.nodes[0].right(0);
  ASSERT_FALSE(isLeafRef(l));
  ASSERT_FALSE(isLeafRef(r));
  const NodeRef ll = t.nodes[l].left(l), lr = t.nodes[l].right(l), rl = t.nodes[r].left(r), rr = t.nodes[r].right(r);
  auto pre = [&](NodeRef n) { return preorderOf(t, n); };
  auto rec = [&](std::vector<std::pair<NodeRef, CutVisibility>> cut) {
    CutRecord c;
    c.valid = true;
    for (auto [n, v] : cut) {
      c.entries.push_back(CutRecord::pack(pre(n), v));
      c.nodes.push_back(n);
      c.factor.push_back(1);
    }
    c.treeBegin = {0, uint32_t(c.entries.size())};
    return c;
  };
  const CutVisibility V = CutVisibility::Visible, O = CutVisibility::Occluded;
  CutRecord a = rec({{ll, V}, {lr, O}, {r, V}});
  CutRecord b = rec({{l, O}, {rl, V}, {rr, V}});
  ASSERT_EQ(byPre[pre(rr)], rr);
  const CutRecord* ab[2] = {&a, &b};
  MergedCut m;
  lc->mergeSamples(ab, 2, m);
  // ll: A visible, B (through l) occluded: a ray; lr: both occluded, left out of `nodes`;
  // rl and rr: both visible.
  ASSERT_EQ(m.nodes.size(), 3u);
  EXPECT_EQ(m.occluded, 1u);
  EXPECT_EQ(m.nodes[0].node, ll);
  EXPECT_TRUE(m.nodes[0].needsRay);
  EXPECT_TRUE(m.nodes[0].disagree);
  EXPECT_EQ(m.nodes[1].node, rl);
  EXPECT_FALSE(m.nodes[1].needsRay);
  EXPECT_EQ(m.nodes[2].node, rr);
  EXPECT_FALSE(m.nodes[2].needsRay);
  ASSERT_EQ(m.hidden.size(), 1u);
  EXPECT_EQ(m.hidden[0].node, lr);
  // The same merge in the other order of samples.
  const CutRecord* ba[2] = {&b, &a};
  MergedCut m2;
  lc->mergeSamples(ba, 2, m2);
  ASSERT_EQ(m2.nodes.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(m2.nodes[i].node, m.nodes[i].node);
}

// One to four samples that each kept the root, with every visibility and first-order flag:
// the merged node follows the rule of reconstruction.h for each combination (left out when
// every sample found it occluded; a ray where any found it occluded or through glass, or
// none found it visible; the samples' first-order factor averaged where all used one). The
// merge counts these from the samples' packed states at once (mergeCuts), so every sample
// count, and the lanes beyond it, are checked.
TEST(Reconstruction, MergedNodeFollowsEveryCombinationOfItsSamplesStates) {
  LightSet lights = cloud(64, LightType::Omni, 5);
  LightForest forest = buildLightForest(lights);
  auto lc = makeLightcuts(lights, forest, CutOptions{});
  const NodeRef root = forest.trees[0].root;
  const CutVisibility kinds[4] = {CutVisibility::Visible, CutVisibility::Occluded, CutVisibility::Untested,
                                  CutVisibility::Partial};
  CutRecord records[4];
  MergedCut m;
  int merges = 0;
  for (int count = 1; count <= 4; ++count) {
    int combos = 1;
    for (int i = 0; i < count; ++i) combos *= 8;
    for (int combo = 0; combo < combos; ++combo) {
      int visible = 0, occluded = 0, partial = 0, firstOrder = 0;
      float factorSum = 0;
      const CutRecord* samples[4];
      for (int i = 0, code = combo; i < count; ++i, code /= 8) {
        const CutVisibility v = kinds[code % 4];
        const bool fo = code / 4 % 2 != 0;
        CutRecord& r = records[i];
        r.clear();
        r.valid = true;
        r.entries = {CutRecord::pack(0, v, fo)};
        r.nodes = {root};
        r.factor = {1.0f + 0.25f * float(i)};
        r.treeBegin = {0, 1};
        r.finish();
        samples[i] = &r;
        visible += v == CutVisibility::Visible;
        occluded += v == CutVisibility::Occluded;
        partial += v == CutVisibility::Partial;
        firstOrder += fo;
        factorSum += r.factor[0];
      }
      lc->mergeSamples(samples, count, m);
      ++merges;
      SCOPED_TRACE(::testing::Message() << "samples " << count << ", combination " << combo);
      if (occluded == count) {
        EXPECT_TRUE(m.nodes.empty());
        EXPECT_EQ(m.occluded, 1u);
        continue;
      }
      ASSERT_EQ(m.nodes.size(), 1u);
      EXPECT_EQ(m.occluded, 0u);
      const MergedCut::Node& n = m.nodes[0];
      EXPECT_EQ(n.node, root);
      EXPECT_EQ(n.needsRay, occluded > 0 || partial > 0 || visible == 0);
      EXPECT_EQ(n.disagree, occluded > 0 || partial > 0);
      EXPECT_EQ(n.batched, !n.needsRay);
      EXPECT_FLOAT_EQ(n.factor, firstOrder == count ? factorSum / float(count) : 1.0f);
    }
  }
  EXPECT_EQ(merges, 8 + 64 + 512 + 4096);
}

// Spots whose cone edges cross the receiver: a small cluster across an edge is a 0-or-all
// sample of its representative, so the samples' cuts estimate it by its exact sum
// (CutRecord::summed), and a point between them must too, all but the dimmest, whose
// error adds up to at most an eighth of the error limit (kUnsummedShare, evaluator.cpp).
// Over 40 cells of four samples 0.15 apart on the floor, the points between them against
// the exact sum (no occluders): the mean error 0.08% with summed nodes, 0.41% without, the
// worst 0.24% (an eighth of --error 0.02 is 0.25%).
TEST(Reconstruction, NodesTheSamplesSummedAreSummedBetweenThem) {
  LightSet lights = cloud(800, LightType::Spot, 23);
  lights.groups[0].falloff.cosCutoff = std::cos(0.3f);  // 17 degrees: footprints ~1.5 across
  lights.groups[0].falloff.exponent = 1;
  LightForest forest = buildLightForest(lights);
  auto lc = makeLightcuts(lights, forest, CutOptions{});
  auto brute = makeBruteForce(lights);
  Rng rng(5, 1);
  double errWith = 0, errWithout = 0, worstWith = 0;
  int points = 0, summedNodes = 0;
  for (int cell = 0; cell < 40; ++cell) {
    const float x0 = rng.uniform() * 3 - 1.5f, z0 = rng.uniform() * 3 - 1.5f, d = 0.15f;
    CutRecord recs[4];
    for (int k = 0; k < 4; ++k) {
      CountingVisibility v(open);
      EvalStats st;
      lc->evaluateRecorded(point(Vec3(x0 + d * (k & 1), 0, z0 + d * (k >> 1))), v, st, recs[k]);
    }
    const CutRecord* four[4] = {&recs[0], &recs[1], &recs[2], &recs[3]};
    MergedCut with;
    lc->mergeSamples(four, 4, with);
    for (const MergedCut::Node& n : with.nodes) summedNodes += n.summed;
    CutRecord plain[4];
    for (int k = 0; k < 4; ++k) {
      plain[k] = recs[k];
      plain[k].summed.clear();  // as before summed nodes were recorded
    }
    const CutRecord* fourPlain[4] = {&plain[0], &plain[1], &plain[2], &plain[3]};
    MergedCut without;
    lc->mergeSamples(fourPlain, 4, without);
    for (float u : {0.3f, 0.5f, 0.8f}) {
      const ShadingPoint sp = point(Vec3(x0 + d * u, 0, z0 + d * (1 - u)));
      CountingVisibility v(open);
      EvalStats st;
      const double exact = luminance(brute->evaluate(sp, v, st).radiance);
      if (!(exact > 0)) continue;
      const double a = std::fabs(luminance(lc->reconstruct(sp, v, st, with).radiance) / exact - 1);
      const double b = std::fabs(luminance(lc->reconstruct(sp, v, st, without).radiance) / exact - 1);
      errWith += a;
      errWithout += b;
      worstWith = std::max(worstWith, a);
      ++points;
    }
  }
  ASSERT_GT(points, 60);
  EXPECT_GT(summedNodes, 40) << "cone edges cross the cells: some nodes are summed";
  errWith /= points;
  errWithout /= points;
  EXPECT_LT(errWith, 0.5 * errWithout) << "mean error with summed nodes " << errWith << ", without " << errWithout;
  EXPECT_LT(worstWith, 1.5 * 0.125 * CutOptions{}.errorRatio);
}

}  // namespace
}  // namespace lc::lightcuts
