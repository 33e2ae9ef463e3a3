#include "lightcuts/evaluator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <queue>
#include <utility>

#include "core/error.h"
#include "core/rng.h"
#include "lightcuts/bounds.h"
#include "lightcuts/exact_sum.h"
#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::cloud;
using test_lights::point;

struct Unoccluded : Visibility {
  Color operator()(const Vec3&, float) override { return Color(1); }
};

// Blocks every direction with a negative x component (half the lights of a sphere).
struct HalfBlocked : Visibility {
  Color operator()(const Vec3& wi, float) override { return wi.x < 0 ? Color(0) : Color(1); }
};

// The visibility coin's rates by size class: a class with enough refinements keeps its own
// rate, one with few pools the larger classes' (then the smaller ones', at the top), and
// none falls below the floor's share of the rate over all of them.
TEST(CoinRates, EachSizeClassTakesItsOwnRatePooledWhereItHasFew) {
  constexpr int n = detail::kCoinSizeClasses;
  uint32_t tested[n] = {}, split[n] = {};
  tested[1] = 100, split[1] = 3;  // clusters of 2-3 lights: 3%
  tested[2] = 100, split[2] = 6;  // 4-7: 6%
  tested[3] = 10, split[3] = 2;   // 8-15: too few alone
  tested[4] = 10, split[4] = 4;   // 16-31: too few, and nothing above
  double rates[n];
  detail::coinRatesBySize(tested, split, 16, 0.0, rates);
  EXPECT_DOUBLE_EQ(rates[1], 0.03);
  EXPECT_DOUBLE_EQ(rates[2], 0.06);
  EXPECT_DOUBLE_EQ(rates[3], 6.0 / 20);   // with class 4
  EXPECT_DOUBLE_EQ(rates[4], 6.0 / 20);   // with class 3, below it
  EXPECT_DOUBLE_EQ(rates[0], 0.03);       // none of its own: class 1's
  EXPECT_DOUBLE_EQ(rates[10], 6.0 / 20);  // none above: down to class 3
  // The floor: half the rate over all 220 refinements (15 splits).
  detail::coinRatesBySize(tested, split, 16, 0.5, rates);
  EXPECT_DOUBLE_EQ(rates[1], 0.5 * 15 / 220);
  EXPECT_DOUBLE_EQ(rates[2], 0.06);
  // No refinements tested: no rate.
  const uint32_t none[n] = {};
  detail::coinRatesBySize(none, none, 16, 0.5, rates);
  for (double r : rates) EXPECT_EQ(r, 0.0);
}

TEST(BruteForce, SumsEveryLight) {
  LightSet s = cloud(50, LightType::Omni, 1);
  auto bf = makeBruteForce(s);
  Unoccluded vis;
  EvalStats st;
  ShadingPoint sp = point(Vec3(0, 0, 0));
  EvalResult r = bf->evaluate(sp, vis, st);
  Color expect(0);
  for (const Light& l : s.lights) {
    Color mg;
    Vec3 wi;
    float d;
    if (lightContribution(l, s.groups[0], sp, mg, wi, d)) expect += mg * l.intensity;
  }
  EXPECT_NEAR(r.radiance.x, expect.x, 1e-6f);
  EXPECT_NEAR(r.radiance.y, expect.y, 1e-6f);
  EXPECT_EQ(r.cutSize, 50u);
  EXPECT_EQ(st.shadowRays, 50u);
}

// One point light over a plane: the closed form of the course's Phong model.
TEST(BruteForce, MatchesClosedFormPhong) {
  LightSet s;
  LightGroup g;
  g.atten = Attenuation{0.2f, 0.3f, 0.1f, kInf};
  s.groups.push_back(g);
  Light l;
  l.position = Vec3(1, 2, 0);
  l.intensity = Color(1, 0.5f, 0.25f);
  s.lights.push_back(l);
  ShadingPoint sp = point(Vec3(0, 0, 0));
  auto bf = makeBruteForce(s);
  Unoccluded vis;
  EvalStats st;
  Color got = bf->evaluate(sp, vis, st).radiance;
  float d = std::sqrt(5.0f);
  Vec3 L = Vec3(1, 2, 0) / d;
  float atten = std::min(1.0f, 1 / (0.2f + 0.3f * d + 0.1f * d * d));
  Color expect = (sp.kd * dot(sp.n, L) + sp.ks * std::pow(dot(sp.r, L), 10.0f)) * atten * l.intensity;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expect[c], 1e-6f);
}

class CutMethods : public ::testing::TestWithParam<LightType> {};

TEST_P(CutMethods, LeafCutEqualsBruteForce) {
  LightSet s = cloud(300, GetParam(), 3);
  LightForest f = buildLightForest(s);
  auto bf = makeBruteForce(s);
  auto lcut = makeLightcuts(s, f, CutOptions{0.0f, 1 << 30});
  HalfBlocked vis;
  EvalStats st;
  for (int i = 0; i < 20; ++i) {
    ShadingPoint sp = point(Vec3(float(i) * 0.2f - 2, 0, 0.1f * float(i)));
    Color a = bf->evaluate(sp, vis, st).radiance;
    EvalResult b = lcut->evaluate(sp, vis, st);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b.radiance[c], 1e-5f * (a[c] + 1e-6f));
  }
}

TEST_P(CutMethods, ErrorStaysNearTheThresholdAndCutsAreSmall) {
  LightSet s = cloud(20000, GetParam(), 4);
  LightForest f = buildLightForest(s);
  auto bf = makeBruteForce(s);
  auto walter = makeLightcuts(s, f, CutOptions{0.02f, 1000, CutCriterion::Walter});
  auto total = makeLightcuts(s, f, CutOptions{0.02f, 1000, CutCriterion::Total});
  Unoccluded vis;
  EvalStats st, stw, stt;
  double worstW = 0, sumW = 0, worstT = 0;
  for (int i = 0; i < 20; ++i) {
    ShadingPoint sp = point(Vec3(float(i) * 0.3f - 3, 0, 0.2f * float(i) - 2));
    double a = luminance(bf->evaluate(sp, vis, st).radiance);
    double w = std::fabs(luminance(walter->evaluate(sp, vis, stw).radiance) - a) / a;
    double t = std::fabs(luminance(total->evaluate(sp, vis, stt).radiance) - a) / a;
    worstW = std::max(worstW, w);
    sumW += w;
    worstT = std::max(worstT, t);
  }
  // Walter's rule keeps each node's bound under 2% of the total; in this cloud of equally
  // distant lights many nodes sit near that threshold and their errors add up, but they
  // still average under it. The total criterion keeps every point under 2%.
  EXPECT_LT(sumW / 20, 0.02);
  EXPECT_LT(worstW, 0.06);
  EXPECT_LT(worstT, 0.02);
  EXPECT_LT(double(stw.cutNodes) / double(stw.shadingPoints), 0.05 * 20000);
  EXPECT_LE(double(stt.cutNodes) / double(stt.shadingPoints), 1000);
  EXPECT_GE(stt.cutNodes, stw.cutNodes);
}

// Twenty points under a cloud of 20,000 lights, half of whose rays are blocked: `check`
// gets each point, its brute-force luminance and its cut (a function of the point, for the
// knobs of ShadingPoint).
template <class Check>
void forCloudPoints(LightType type, Check check) {
  LightSet s = cloud(20000, type, 4);
  LightForest f = buildLightForest(s);
  auto bf = makeBruteForce(s);
  auto lc = makeLightcuts(s, f, CutOptions{0.02f, 4000});
  HalfBlocked vis;
  EvalStats st;
  auto cut = [&](const ShadingPoint& sp) { return lc->evaluate(sp, vis, st); };
  for (int i = 0; i < 20; ++i) {
    ShadingPoint sp = point(Vec3(float(i) * 0.3f - 3, 0, 0.2f * float(i) - 2));
    check(i, sp, double(luminance(bf->evaluate(sp, vis, st).radiance)), cut);
  }
}

// The error floor (ShadingPoint::errorFloor): below it the criterion is an absolute error
// of errorRatio x floor. A floor of 0 is the published criterion, bit for bit; a floor
// far above the point's light stops the cut early and keeps its error within a few times
// errorRatio x floor; one far below changes nothing.
TEST_P(CutMethods, ErrorFloorBoundsAbsoluteError) {
  forCloudPoints(GetParam(), [](int i, ShadingPoint sp, double exact, auto cut) {
    EvalResult none = cut(sp);
    if (!(exact > 0)) return;  // all hidden: no floor to scale
    sp.errorFloor = 0;
    EvalResult zero = cut(sp);
    EXPECT_EQ(none.radiance, zero.radiance);
    EXPECT_EQ(none.cutSize, zero.cutSize);
    sp.errorFloor = float(exact * 1e-3);
    EvalResult low = cut(sp);
    EXPECT_EQ(low.radiance, none.radiance);
    const float floor = float(exact * 20);
    sp.errorFloor = floor;
    EvalResult high = cut(sp);
    EXPECT_LT(high.cutSize, none.cutSize);
    // The total criterion's error spreads sum to 1.6 x the limit; the estimate errs by less.
    EXPECT_LT(std::fabs(luminance(high.radiance) - exact), 3 * 0.02 * floor) << i;
  });
}

// ShadingPoint::minError (the error floor's pre-pass): at or below the evaluator's --error
// it changes nothing, bit for bit; above it the cut is held to that looser error instead,
// so it is smaller and errs within it.
TEST_P(CutMethods, MinErrorLoosensTheCutOnlyAboveTheEvaluatorsError) {
  int looser = 0;
  forCloudPoints(GetParam(), [&looser](int i, ShadingPoint sp, double exact, auto cut) {
    EvalResult none = cut(sp);
    sp.minError = 0.02f;
    EvalResult same = cut(sp);
    EXPECT_EQ(none.radiance, same.radiance);
    EXPECT_EQ(none.cutSize, same.cutSize);
    sp.minError = 0.1f;
    EvalResult loose = cut(sp);
    EXPECT_LE(loose.cutSize, none.cutSize);
    looser += loose.cutSize < none.cutSize;
    if (exact > 0) {
      EXPECT_LT(std::fabs(luminance(loose.radiance) - exact), 0.1 * exact) << i;
    }
  });
  EXPECT_GE(looser, 15);
}

// Clear tests pay from one pass in kClearMinLights (16), once there are enough to judge.
TEST(ClearTests, PayFromOnePassInSixteen) {
  EXPECT_TRUE(clearTestsPay(0, 0));
  EXPECT_TRUE(clearTestsPay(999, 0));  // too few to tell
  EXPECT_FALSE(clearTestsPay(1000, 0));
  EXPECT_TRUE(clearTestsPay(1600, 100));
  EXPECT_FALSE(clearTestsPay(1600, 99));
  EXPECT_TRUE(clearTestsPay(49000, 49000));
}

// ShadingPoint::clearTests off: the cut tests no cluster; where no test would pass (no
// implementation of boxClear) its light is the same bit for bit.
TEST(Lightcuts, ClearTestsOnlyWhereThePointAllowsThem) {
  LightSet s = cloud(20000, LightType::Omni, 4);
  LightForest f = buildLightForest(s);
  auto lc = makeLightcuts(s, f, CutOptions{0.02f, 4000});
  HalfBlocked vis;
  ShadingPoint sp = point(Vec3(0.3f, 0, -0.5f));
  EvalStats on, off;
  EvalResult a = lc->evaluate(sp, vis, on);
  sp.clearTests = false;
  EvalResult b = lc->evaluate(sp, vis, off);
  EXPECT_GT(on.clearTests, 0u);
  EXPECT_EQ(off.clearTests, 0u);
  EXPECT_EQ(a.radiance, b.radiance);
  EXPECT_EQ(a.cutSize, b.cutSize);
}

INSTANTIATE_TEST_SUITE_P(Kinds, CutMethods, ::testing::Values(LightType::Omni, LightType::Oriented),
                         [](const auto& info) { return std::string(lightTypeName(info.param)); });

// With no threshold a cut grows to --max-cut by always refining the node with the largest
// bound: replaying that greedy order with std::priority_queue must give the same cut (this
// checks the evaluator's own heap and its keys).
TEST(Lightcuts, RefinesTheLargestBoundFirst) {
  LightSet s = cloud(2000, LightType::Oriented, 6);
  LightForest f = buildLightForest(s);
  ASSERT_EQ(f.trees.size(), 1u);
  const LightTree& t = f.trees[0];
  const LightGroup& g = s.groups[0];
  Unoccluded vis;
  ShadingPoint sp = point(Vec3(0.3f, 0, -0.2f));
  BoundFrames fr(sp);
  auto unit = [&](NodeRef ni) {
    Color mg;
    Vec3 wi;
    float d;
    return lightContribution(s.lights[t.repOf(ni)], g, sp, mg, wi, d) ? mg : Color(0);
  };
  for (uint32_t maxCut : {1u, 2u, 17u, 100u, 333u, 1500u}) {
    std::priority_queue<std::pair<float, NodeRef>> heap;
    std::vector<NodeRef> known;  // small untested nodes whose exact sum was taken
    Color expect(0);
    uint32_t size = 0;
    auto add = [&](NodeRef ni) {
      ++size;
      const LightNode n = t.node(s, ni);
      float b = isLeafRef(ni) ? 0.0f : luminance(clusterBound(n, t.type, g, sp, fr));
      if (b > 0)
        heap.push({b, ni});
      else
        expect += unit(ni) * n.intensity;
    };
    add(t.root);
    while (!heap.empty() && size < maxCut) {
      auto [b, ni] = heap.top();
      heap.pop();
      // A small cluster whose representative contributes nothing goes back once, with its
      // exact unshadowed sum as its bound (kExactSumMaxLights).
      if (isBlack(unit(ni)) && t.nodes[ni].lights() <= kExactSumMaxLights && std::find(known.begin(), known.end(), ni) == known.end()) {
        known.push_back(ni);
        const float u = luminance(unshadowedSum(s, t, ni, sp).sum);
        if (u < b) {
          heap.push({u, ni});
          continue;
        }
      }
      --size;
      add(t.nodes[ni].left(ni));
      add(t.nodes[ni].right(ni));
    }
    for (; !heap.empty(); heap.pop()) expect += unit(heap.top().second) * t.node(s, heap.top().second).intensity;
    // The representative's estimate, as the replay computes it.
    auto lcut = makeLightcuts(s, f, CutOptions{0.0f, int(maxCut), CutCriterion::Walter, Estimator::Representative});
    EvalStats st;
    EvalResult r = lcut->evaluate(sp, vis, st);
    EXPECT_EQ(r.cutSize, size) << "max cut " << maxCut;
    EXPECT_NEAR(luminance(r.radiance), luminance(expect), 1e-5f * luminance(expect)) << "max cut " << maxCut;
  }
}

// Second samples (kSecondSampleShare): behind a straight shadow edge through a cloud, the
// bright clusters whose representatives are on the edge's lit side are checked with a second
// light's ray before the cut stops, and those found partly hidden are refined. Over the
// points, the cut's errors against brute force fall (skipping points the edge hides whole).
TEST(Lightcuts, SecondSamplesFindEdgesTheRepresentativesMissed) {
  LightSet s = cloud(400, LightType::Oriented, 11);
  LightForest f = buildLightForest(s);
  // Hidden where the direction's x is below a slope through the cloud: an edge no cluster
  // boundary follows.
  struct Edge : Visibility {
    Color operator()(const Vec3& wi, float) override { return wi.x < 0.3f * wi.z - 0.1f ? Color(0) : Color(1); }
  } vis;
  auto brute = makeBruteForce(s);
  CutOptions off;
  off.secondSamples = false;
  auto lcOn = makeLightcuts(s, f, CutOptions{}), lcOff = makeLightcuts(s, f, off);
  Rng r(5, 1);
  double errOn = 0, errOff = 0, worstOn = 0, worstOff = 0;
  EvalStats stOn, stOff, stB;
  for (int i = 0; i < 200; ++i) {
    ShadingPoint sp = point(Vec3(r.uniform() * 6 - 3, 0, r.uniform() * 6 - 3));
    const double ref = luminance(brute->evaluate(sp, vis, stB).radiance);
    if (!(ref > 0)) continue;
    const double eOn = std::abs(luminance(lcOn->evaluate(sp, vis, stOn).radiance) / ref - 1);
    const double eOff = std::abs(luminance(lcOff->evaluate(sp, vis, stOff).radiance) / ref - 1);
    errOn += eOn, errOff += eOff, worstOn = std::max(worstOn, eOn), worstOff = std::max(worstOff, eOff);
  }
  EXPECT_EQ(stOff.secondSamples, 0u);
  EXPECT_GT(stOn.secondSamplesHidden, 0u);
  // 400 lights, 200 points: 12 of 1,648 second samples hidden, 3% more rays; the worst
  // point 0.80% -> 0.57% off, the mean 0.085% -> 0.082%.
  EXPECT_LT(errOn, errOff);
  EXPECT_LT(worstOn, worstOff);
}

// A small cluster whose representative faces away from the point (no shadow ray) is off by
// at most its exact unshadowed sum, not its bound over its box and cone: eight lights above
// the point, seven facing up (away) and one, a hundred times dimmer, tilted to face it at
// a grazing angle. Beside a bright light, the cluster's bound is over the error budget and
// its exact sum far under it: the cut keeps it whole, and the image is exact.
TEST(Lightcuts, AClusterFacingAwayStopsAtItsExactSum) {
  LightSet s;
  s.groups.push_back(LightGroup{});
  for (int i = 0; i < 8; ++i) {
    Light l;
    l.type = LightType::Oriented;
    l.position = Vec3(0.05f * float(i % 4) - 0.075f, 1 + 0.02f * float(i / 4), 0.03f * float(i % 3));
    const bool facing = i == 5;
    l.direction = facing ? normalize(Vec3(1, -0.2f, 0)) : Vec3(0, 1, 0);
    l.intensity = Color(facing ? 0.1f : 10.0f);
    s.lights.push_back(l);
  }
  Light bright;  // an omni light: a tree of its own
  bright.type = LightType::Omni;
  bright.position = Vec3(1, 2, 0);
  bright.intensity = Color(1);
  s.lights.push_back(bright);
  ShadingPoint sp = point(Vec3(0, 0, 0));
  LightForest f = buildLightForest(s);
  ASSERT_EQ(f.trees.size(), 2u);
  const LightTree& t = f.trees[0].type == LightType::Oriented ? f.trees[0] : f.trees[1];
  ASSERT_FALSE(isLeafRef(t.root));
  Color mg;
  Vec3 wi;
  float d;
  ASSERT_FALSE(lightContribution(s.lights[t.nodes[t.root].rep], s.groups[0], sp, mg, wi, d))
      << "the representative must face away";
  float exact = 0;
  for (int i = 0; i < 8; ++i)
    if (lightContribution(s.lights[i], s.groups[0], sp, mg, wi, d)) exact += luminance(mg * s.lights[i].intensity);
  BoundFrames fr(sp);
  const float bound = luminance(clusterBound(t.nodes[t.root], t.type, s.groups[0], sp, fr));
  ASSERT_GT(exact, 0.0f);
  ASSERT_GT(bound, 100 * exact);
  // The bright light puts the budget (2% of the total) halfway between the two, in ratio.
  ASSERT_TRUE(lightContribution(bright, s.groups[0], sp, mg, wi, d));
  s.lights.back().intensity = Color(std::sqrt(bound * exact) / 0.02f / luminance(mg));
  f = buildLightForest(s);
  Unoccluded vis;
  EvalStats st, sb;
  auto lcut = makeLightcuts(s, f, CutOptions{0.02f});
  EvalResult r = lcut->evaluate(sp, vis, st);
  Color want = makeBruteForce(s)->evaluate(sp, vis, sb).radiance;
  EXPECT_EQ(r.cutSize, 2u);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.radiance[c], want[c], 1e-5f * want[c]);
  // A reconstruction sample refines it as before: points between samples estimate an
  // untested node by its representative alone.
  CutRecord rec;
  EvalStats sr;
  EXPECT_GT(lcut->evaluateRecorded(sp, vis, sr, rec).cutSize, 2u);
}

// A chandelier: a tight clump of lights far above the points, with nothing between, which
// the scene proves (Visibility::boxClear): its clusters are clear, their light within their
// lower and upper bounds, which lie close together so far away. Ordered by their upper
// bounds (Walter's rule), the clump's clusters were refined until each held under 2% of
// the light, as if it could be hidden; ordered by their spreads, a full cut stops far
// sooner, as close to brute force. A recorded cut keeps the upper bounds (reconstruction's
// points borrow visibility from its finer clusters).
struct AllClear : Unoccluded {
  bool boxClear(const Vec3&, const Vec3&, uint32_t&) override { return true; }
};

TEST(Lightcuts, ClearClustersAreOrderedByTheirSpreads) {
  LightSet s = cloud(3000, LightType::Omni, 12);
  for (Light& l : s.lights) l.position = Vec3(0, 6, 0) + (l.position - Vec3(0, 2.5f, 0)) * 0.05f;
  LightForest f = buildLightForest(s);
  auto lcut = makeLightcuts(s, f, CutOptions{0.02f});
  auto brute = makeBruteForce(s);
  AllClear vis;
  Rng r(5, 1);
  uint64_t fullNodes = 0, recordedNodes = 0;
  for (int i = 0; i < 20; ++i) {
    ShadingPoint sp = point(Vec3(r.uniform() * 4 - 2, 0, r.uniform() * 4 - 2));
    EvalStats sf, sr, sb;
    EvalResult full = lcut->evaluate(sp, vis, sf);
    CutRecord rec;
    EvalResult recorded = lcut->evaluateRecorded(sp, vis, sr, rec);
    const float want = luminance(brute->evaluate(sp, vis, sb).radiance);
    EXPECT_NEAR(luminance(full.radiance), want, 0.02f * want) << i;
    EXPECT_NEAR(luminance(recorded.radiance), want, 0.02f * want) << i;
    EXPECT_GT(sf.clearedClusters, 0u);
    fullNodes += full.cutSize;
    recordedNodes += recorded.cutSize;
  }
  EXPECT_LT(double(fullNodes), 0.5 * double(recordedNodes)) << fullNodes << " " << recordedNodes;
}

// A cut that runs out of --max-cut nodes before its bound holds is counted; one that holds
// its bound, or reaches every light, is not.
TEST(Lightcuts, CountsCutsStoppedByTheBudget) {
  LightSet s = cloud(2000, LightType::Oriented, 6);
  LightForest f = buildLightForest(s);
  Unoccluded vis;
  ShadingPoint sp = point(Vec3(0.3f, 0, -0.2f));
  auto count = [&](float error, int maxCut) {
    auto lc = makeLightcuts(s, f, CutOptions{error, maxCut});
    EvalStats st;
    lc->evaluate(sp, vis, st);
    return st.cutsAtMaxCut;
  };
  EXPECT_EQ(count(0.0f, 100), 1u);      // an exact cut wanted, 100 nodes allowed
  EXPECT_EQ(count(0.0f, 1 << 30), 0u);  // every light reached
  EXPECT_EQ(count(0.02f, 4000), 0u);    // the bound holds well before 4000
}

TEST(CourseCuts, ZeroThresholdReachesEveryLight) {
  LightSet s = cloud(200, LightType::Omni, 5);
  LightForest f = buildLightForest(s, TreeBuildOptions{TreeBuilder::Course, 1});
  auto bf = makeBruteForce(s);
  auto seed = makeCourseCuts(s, f, CutOptions{0.0f, 1 << 30});
  Unoccluded vis;
  EvalStats st;
  ShadingPoint sp = point(Vec3(0.5f, 0, 0));
  Color a = bf->evaluate(sp, vis, st).radiance;
  EvalResult b = seed->evaluate(sp, vis, st);
  EXPECT_EQ(b.cutSize, 200u);
  EXPECT_NEAR(luminance(a), luminance(b.radiance), 1e-5f * luminance(a));
}

// The seed's cuts over an agglomerative tree, which stores no seed data: the evaluator
// computes it, and every cut and value equals the one over the data stored at build time.
TEST(CourseCuts, OnDemandSeedDataCutsAsStored) {
  LightSet s = cloud(500, LightType::Oriented, 9);
  TreeBuildOptions eager;
  eager.courseData = true;
  LightForest stored = buildLightForest(s, eager);
  LightForest lazy = buildLightForest(s);
  ASSERT_TRUE(lazy.trees[0].course.empty());
  auto a = makeCourseCuts(s, stored, CutOptions{0.3f, 1000});
  auto b = makeCourseCuts(s, lazy, CutOptions{0.3f, 1000});
  HalfBlocked vis;
  for (float x : {0.5f, -2.0f, 3.0f}) {
    ShadingPoint sp = point(Vec3(x, 0.25f, 0));
    EvalStats sa, sb;
    EvalResult ra = a->evaluate(sp, vis, sa), rb = b->evaluate(sp, vis, sb);
    EXPECT_EQ(ra.cutSize, rb.cutSize);
    EXPECT_EQ(ra.radiance, rb.radiance);
    EXPECT_EQ(sa.shadowRays, sb.shadowRays);
  }
}

TEST(CourseCuts, BlockedRepresentativeFallsBackToChildren) {
  LightSet s;
  s.groups.push_back(LightGroup{});
  for (float x : {-1.0f, 1.0f}) {
    Light l;
    l.position = Vec3(x, 5, 0);
    l.intensity = Color(1);
    s.lights.push_back(l);
  }
  LightForest f = buildLightForest(s, TreeBuildOptions{TreeBuilder::Course, 1});
  // The centroid light's visibility is taken toward the root's representative light:
  // block exactly that light; the other child is visible.
  float blockedX = s.lights[f.trees[0].repOf(f.trees[0].root)].position.x;
  struct BlockOne : Visibility {
    float x;
    Color operator()(const Vec3& wi, float) override { return wi.x * x > 0 ? Color(0) : Color(1); }
  } vis;
  vis.x = blockedX;
  auto seed = makeCourseCuts(s, f, CutOptions{10.0f, 1000});
  EvalStats st;
  ShadingPoint sp = point(Vec3(0, 0, 0));
  sp.ks = Color(0);
  EvalResult r = seed->evaluate(sp, vis, st);
  EXPECT_EQ(r.cutSize, 2u);  // the two children replaced the blocked centroid light
  // Exactly the visible light's contribution.
  Color mg;
  Vec3 wi;
  float d;
  const Light& visible = s.lights[blockedX < 0 ? 1 : 0];
  ASSERT_TRUE(lightContribution(visible, s.groups[0], sp, mg, wi, d));
  EXPECT_NEAR(luminance(r.radiance), luminance(mg * visible.intensity), 1e-6f);
}

TEST(Methods, ParseNames) {
  EXPECT_EQ(parseMethod("brute"), Method::Brute);
  EXPECT_EQ(parseMethod("seed"), Method::Course);
  EXPECT_THROW(parseMethod("fast"), Error);
}
}  // namespace
}  // namespace lc::lightcuts

namespace lc::lightcuts {
namespace {

// A convex opaque ball (object 7) between the shading point and its lights.
struct Ball : Visibility {
  Vec3 from, centre;
  float radius;
  int hits = 0;
  Ball(Vec3 f, Vec3 c, float r) : from(f), centre(c), radius(r) {}
  // Distance along wi to the ball, or infinity.
  float distance(const Vec3& wi) const {
    Vec3 oc = from - centre;
    float b = dot(oc, wi), c = dot(oc, oc) - radius * radius;
    float disc = b * b - c;
    if (disc < 0) return kInf;
    float t = -b - std::sqrt(disc);
    return t > 0 ? t : kInf;
  }
  Color operator()(const Vec3& wi, float dist) override { return distance(wi) < dist ? Color(0) : Color(1); }
  Color trace(const Vec3& wi, float dist, int& blocker, float& tHit) override {
    tHit = distance(wi);
    blocker = tHit < dist ? 7 : kVisible;
    return blocker == 7 ? Color(0) : Color(1);
  }
};

// The same, as an occluder of unknown shape: probes can prove nothing.
struct UnknownBall : Ball {
  using Ball::Ball;
  Color trace(const Vec3& wi, float dist, int& blocker, float& tHit) override {
    return Visibility::trace(wi, dist, blocker, tHit);
  }
};

CutOptions withProbes(bool on, float error = 0.02f) {
  CutOptions o;
  o.errorRatio = error;
  o.maxCut = 1 << 20;
  o.visibilityProbes = on;
  return o;
}

// Every light hidden behind a convex ball: the point gets nothing, and a cluster proven
// hidden is not refined; without probes (or with an occluder it cannot prove convex) the
// cut refines to every light, since no bound ever falls below 2% of nothing.
TEST(VisibilityProbes, AHiddenCloudStaysOneCluster) {
  LightSet s = cloud(2000, LightType::Omni, 21);
  LightForest f = buildLightForest(s);
  ShadingPoint sp = point(Vec3(0, 0, 0));
  Ball ball(sp.p, Vec3(0, 0.5f, 0), 0.47f);
  auto on = makeLightcuts(s, f, withProbes(true));
  auto off = makeLightcuts(s, f, withProbes(false));
  EvalStats son, soff, sunk;
  EvalResult a = on->evaluate(sp, ball, son);
  EvalResult b = off->evaluate(sp, ball, soff);
  UnknownBall unknown(sp.p, Vec3(0, 0.5f, 0), 0.47f);
  EvalResult c = on->evaluate(sp, unknown, sunk);
  EXPECT_EQ(luminance(a.radiance), 0.0f);
  EXPECT_EQ(luminance(b.radiance), 0.0f);
  EXPECT_EQ(son.hiddenClusters, 1u);
  EXPECT_EQ(a.cutSize, 1u);
  EXPECT_EQ(b.cutSize, 2000u);
  EXPECT_EQ(sunk.hiddenClusters, 0u);
  EXPECT_EQ(c.cutSize, 2000u);
}

// The same ball, with its bounds for the probes' test without rays (Visibility::blockerBox).
struct BoxedBall : Ball {
  using Ball::Ball;
  bool blockerBox(int blocker, Vec3& lo, Vec3& hi) const override {
    if (blocker != 7) return false;
    lo = centre - Vec3(radius * 1.0001f);
    hi = centre + Vec3(radius * 1.0001f);
    return true;
  }
};

// A probe whose corner ray cannot meet the blocker's box fails before any ray; the answers
// are the rays' own, so the cuts are the same, for fewer probe rays.
TEST(VisibilityProbes, TheBlockersBoxRulesOutProbesWithoutChangingAnswers) {
  LightSet s = cloud(3000, LightType::Omni, 23);
  LightForest f = buildLightForest(s);
  auto lcut = makeLightcuts(s, f, withProbes(true));
  EvalStats traced, boxed;
  for (int i = 0; i < 16; ++i) {
    ShadingPoint sp = point(Vec3(0.25f * float(i) - 2.0f, 0, 0.1f * float(i) - 0.8f));
    const Vec3 c = sp.p + Vec3(0.2f * float(i % 4) - 0.3f, 1.0f, 0.1f);
    Ball ball(sp.p, c, 0.35f);
    BoxedBall boxedBall(sp.p, c, 0.35f);
    EvalResult a = lcut->evaluate(sp, ball, traced);
    EvalResult b = lcut->evaluate(sp, boxedBall, boxed);
    EXPECT_EQ(a.radiance, b.radiance) << i;
    EXPECT_EQ(a.cutSize, b.cutSize) << i;
  }
  EXPECT_EQ(traced.hiddenClusters, boxed.hiddenClusters);
  EXPECT_GT(boxed.hiddenClusters, 0u);
  EXPECT_EQ(traced.probesRuledOut, 0u);
  EXPECT_GT(boxed.probesRuledOut, 0u);
  EXPECT_LT(boxed.probeRays, traced.probeRays);
  EXPECT_EQ(traced.shadowRays - traced.probeRays, boxed.shadowRays - boxed.probeRays);
}

// The same ball, deciding probes itself (Visibility::blocksAll): a segment through the
// ball shrunk by a margin is stopped by it.
struct ExactBall : Ball {
  using Ball::Ball;
  int blocksAll(int blocker, const Vec3* dirs, int n, float tMax) const override {
    if (blocker != 7) return -1;
    const float r = radius - 1e-3f;
    for (int i = 0; i < n; ++i) {
      const Vec3 oc = from - centre;
      const float b = dot(oc, dirs[i]), c = dot(oc, oc) - r * r, disc = b * b - c;
      if (!(disc > 0) || !(-b - std::sqrt(disc) < tMax)) return 0;
    }
    return 1;
  }
};

// Probes decided without rays are as exact as the rays': with a zero threshold every
// cluster not proven hidden is refined to its lights, so the cut must equal brute force.
TEST(VisibilityProbes, ProbesDecidedWithoutRaysAreExact) {
  LightSet s = cloud(3000, LightType::Omni, 24);
  LightForest f = buildLightForest(s);
  auto bf = makeBruteForce(s);
  auto lcut = makeLightcuts(s, f, withProbes(true, 0.0f));
  EvalStats st, sb, traced;
  for (int i = 0; i < 12; ++i) {
    ShadingPoint sp = point(Vec3(0.3f * float(i) - 1.8f, 0, 0.1f * float(i) - 0.5f));
    const Vec3 c = sp.p + Vec3(0.2f * float(i % 4) - 0.3f, 1.0f, 0.1f);
    ExactBall ball(sp.p, c, 0.35f);
    Ball plain(sp.p, c, 0.35f);
    Color want = bf->evaluate(sp, ball, sb).radiance;
    Color got = lcut->evaluate(sp, ball, st).radiance;
    (void)lcut->evaluate(sp, plain, traced);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-5f * (want[k] + 1e-6f)) << i;
  }
  EXPECT_GT(st.hiddenClusters, 0u);
  EXPECT_EQ(st.probeRays, 0u);
  EXPECT_GT(traced.probeRays, 0u);
}

// Partly hidden clouds: with a zero threshold the cut refines everything it cannot prove
// hidden, so it must equal brute force exactly; proven-hidden clusters must have been
// truly hidden.
TEST(VisibilityProbes, ProvenHiddenClustersAreExact) {
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    LightSet s = cloud(3000, type, 22);
    LightForest f = buildLightForest(s);
    auto bf = makeBruteForce(s);
    auto lcut = makeLightcuts(s, f, withProbes(true, 0.0f));
    EvalStats st, sb;
    for (int i = 0; i < 12; ++i) {
      ShadingPoint sp = point(Vec3(0.3f * float(i) - 1.8f, 0, 0.1f * float(i) - 0.5f));
      Ball ball(sp.p, sp.p + Vec3(0.2f * float(i % 4) - 0.3f, 1.0f, 0.1f), 0.35f);
      Color want = bf->evaluate(sp, ball, sb).radiance;
      Color got = lcut->evaluate(sp, ball, st).radiance;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5f * (want[c] + 1e-6f)) << i;
    }
    EXPECT_GT(st.hiddenClusters, 0u) << lightTypeName(type);
    EXPECT_LT(st.cutNodes, sb.cutNodes) << lightTypeName(type);
  }
}
}  // namespace
}  // namespace lc::lightcuts

namespace lc::lightcuts {
namespace {

// Brute force over a bright light and four million dim ones that together give as much
// light (issue 21: a 256-light panel and 8.1M VPLs). All share one point and normal, so
// the sum is (B + N t) f exactly, f one light's contribution per unit intensity. Summed in
// float, each dim term fell below half an ulp of the running sum and was lost.
TEST(Precision, BruteForceOverMillionsOfDimLightsIsExact) {
  constexpr uint32_t kDim = 4'000'000;
  LightSet s;
  s.groups.push_back(LightGroup{});
  Light l;
  l.type = LightType::Oriented;
  l.position = Vec3(0.5f, 3, -0.25f);
  l.direction = Vec3(0, -1, 0);
  const Color bright(1.0f, 0.5f, 0.25f), dim = bright / float(kDim);
  l.intensity = bright;
  s.lights.assign(kDim + 1, l);
  for (uint32_t i = 1; i <= kDim; ++i) s.lights[i].intensity = dim;
  ShadingPoint sp = point(Vec3(0, 0, 0));
  Color unit;
  Vec3 wi;
  float dist;
  ASSERT_TRUE(lightContribution(l, s.groups[0], sp, unit, wi, dist));
  Unoccluded vis;
  EvalStats st;
  EvalResult r = makeBruteForce(s)->evaluate(sp, vis, st);
  for (int k = 0; k < 3; ++k) {
    const double want = double(unit[k]) * (double(bright[k]) + double(kDim) * double(dim[k]));
    EXPECT_NEAR(r.radiance[k], want, 1e-6 * want) << "channel " << k;
  }
  EXPECT_EQ(r.cutSize, kDim + 1);
}

// A forest of more trees than --max-cut must still refine its large tree: each tree after
// the first adds one node to the budget. Counting the roots against it left 1,000 point
// lights as one representative.
TEST(MaxCut, CountsRefinementsBeyondTheRoots) {
  LightSet s = cloud(1000, LightType::Omni, 5);
  const uint32_t spots = uint32_t(kMaxGroupTrees);  // a tree each (more would share one)
  for (uint32_t i = 0; i < spots; ++i) {
    LightGroup g;
    g.falloff.cosCutoff = std::cos(0.3f + 0.02f * float(i));
    s.groups.push_back(g);
    Light l;
    l.type = LightType::Spot;
    l.group = uint16_t(s.groups.size() - 1);
    l.position = Vec3(float(i) * 0.1f - 2, 3, 0);
    l.direction = Vec3(0, -1, 0);
    l.intensity = Color(0.0001f);
    s.lights.push_back(l);
  }
  LightForest f = buildLightForest(s);
  ASSERT_EQ(f.trees.size(), spots + 1);
  auto bf = makeBruteForce(s);
  CutOptions o;
  o.maxCut = 12;  // fewer than the trees
  auto lcut = makeLightcuts(s, f, o);
  Unoccluded vis;
  for (int i = 0; i < 10; ++i) {
    ShadingPoint sp = point(Vec3(float(i) * 0.4f - 2, 0, 0.3f * float(i) - 1.5f));
    EvalStats st;
    EvalResult got = lcut->evaluate(sp, vis, st);
    EXPECT_GT(got.cutSize, spots + 1) << "no refinement at point " << i;
    EXPECT_LE(got.cutSize, spots + 12u);
  }
}

// Spots that each have their own cone share one tree (LightTree::mixedGroups) whose bounds
// use the groups' upper envelope: the cut still converges to brute force, and the default
// error holds.
TEST(MixedGroups, ManyConesShareOneTreeAndStayWithinTheError) {
  LightSet s;
  Rng r(9, 1);
  for (uint32_t i = 0; i < 600; ++i) {
    LightGroup g;
    g.atten = Attenuation{0.2f + 0.3f * r.uniform(), 0.1f * r.uniform(), 0.5f + r.uniform(), kInf};
    float outer = 0.3f + 0.8f * r.uniform();
    g.falloff.cosOuter = std::cos(outer);
    g.falloff.cosInner = std::cos(outer * 0.7f);
    g.falloff.exponent = i % 3 == 0 ? 2.0f : 0.0f;
    s.groups.push_back(g);
    Light l;
    l.type = LightType::Spot;
    l.group = uint16_t(i);
    l.position = Vec3(r.uniform() * 4 - 2, 2 + r.uniform(), r.uniform() * 4 - 2);
    l.direction = normalize(Vec3(r.uniform() - 0.5f, -1, r.uniform() - 0.5f));
    l.intensity = Color(r.uniform(), r.uniform(), r.uniform()) * 0.01f;
    s.lights.push_back(l);
  }
  LightForest f = buildLightForest(s);
  ASSERT_EQ(f.trees.size(), 1u);
  EXPECT_TRUE(f.trees[0].mixedGroups);
  // Every node's bounds hold the sum of its lights' exact contributions.
  const LightTree& t = f.trees[0];
  for (int k = 0; k < 8; ++k) {
    ShadingPoint sp = point(Vec3(r.uniform() * 4 - 2, 0, r.uniform() * 4 - 2));
    BoundFrames fr(sp);
    const std::vector<NodeRef> all = t.preorderNodes();
    for (size_t k7 = 0; k7 < all.size(); k7 += 7) {
      const NodeRef ni = all[k7];
      const double sum = luminance(unshadowedSum(s, t, ni, sp).sum);
      Color lower;
      Color upper = clusterBounds(t.node(s, ni), t.type, t.bound, sp, fr, &lower, nullptr, &t.boundLow);
      EXPECT_GE(double(luminance(upper)), sum * (1 - 1e-5)) << "node " << ni;
      EXPECT_LE(double(luminance(lower)), sum * (1 + 1e-5) + 1e-12) << "node " << ni;
    }
  }
  auto bf = makeBruteForce(s);
  auto exact = makeLightcuts(s, f, CutOptions{0.0f, 1 << 30});
  auto lcut = makeLightcuts(s, f, CutOptions{});
  HalfBlocked vis;
  for (int i = 0; i < 12; ++i) {
    ShadingPoint sp = point(Vec3(float(i) * 0.3f - 1.8f, 0, 0.25f * float(i) - 1.5f));
    EvalStats st;
    Color want = bf->evaluate(sp, vis, st).radiance;
    Color leaves = exact->evaluate(sp, vis, st).radiance;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(leaves[c], want[c], 1e-5f * (1 + want[c]));
    Unoccluded open;
    Color wantOpen = bf->evaluate(sp, open, st).radiance;
    EvalResult got = lcut->evaluate(sp, open, st);
    EXPECT_NEAR(luminance(got.radiance), luminance(wantOpen), 0.02f * luminance(wantOpen)) << "point " << i;
    EXPECT_LT(got.cutSize, 600u);
  }
}

}  // namespace
}  // namespace lc::lightcuts
