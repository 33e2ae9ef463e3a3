#include "lightcuts/evaluator.h"

#include <algorithm>
#include <bit>
#include <utility>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "lightcuts/bounds.h"
#include "lightcuts/bounds_pair.h"
#include "lightcuts/exact_sum.h"

namespace lc::lightcuts {

namespace {

// A recorded cut node: tree << 32 | CutRecord entry, its first-order factor and its node.
struct Recorded {
  uint64_t key;
  float factor;
  NodeRef node;
};

// Sorts a cut's recorded entries by key: by tree, then preorder, unique per entry. For a cut
// of a thousand nodes std::sort was 4% of the church's render (perf); a radix sort over the
// key's significant bits, the tree above the preorder (the entry's 3 low bits are payload),
// takes two or three passes.
void sortRecorded(std::vector<Recorded>& v) {
  if (v.size() < 256) {
    std::sort(v.begin(), v.end(), [](const Recorded& a, const Recorded& b) { return a.key < b.key; });
    return;
  }
  uint32_t maxTree = 0, maxPre = 0;
  for (const Recorded& e : v) {
    maxTree = std::max(maxTree, uint32_t(e.key >> 32));
    maxPre = std::max(maxPre, CutRecord::preorderOf(uint32_t(e.key)));
  }
  const int preBits = std::bit_width(maxPre), bits = preBits + std::bit_width(maxTree);
  auto compact = [preBits](uint64_t k) { return (k >> 32) << preBits | CutRecord::preorderOf(uint32_t(k)); };
  constexpr int kDigit = 10;
  constexpr uint32_t kMask = (1u << kDigit) - 1;
  static thread_local std::vector<Recorded> tmp;
  tmp.resize(v.size());
  uint32_t count[1u << kDigit];
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(std::begin(count), std::end(count), 0u);
    for (const Recorded& e : v) ++count[compact(e.key) >> shift & kMask];
    uint32_t sum = 0;
    for (uint32_t& c : count) sum += std::exchange(c, sum);
    for (const Recorded& e : v) tmp[count[compact(e.key) >> shift & kMask]++] = e;
    v.swap(tmp);
  }
}

// The total criterion bounds the root-sum-square of the cut's error spreads by this factor
// times errorRatio. A node's spread is its upper bound, or, when its representative is
// visible and its sibling's was not hidden, upper minus lower bound (what the estimate of
// an unoccluded cluster can be off by); for a first-order estimate (estimate.h) that is
// scaled by the point's boundary rate (below). The errors have random signs and sit
// inside their spreads; with 1.6, at --error 0.02 over 99% of pixels come within 2% of
// brute force on every scene of the benchmark (the church, whose emitters are mostly
// hidden, is the hardest; docs/LIGHTCUTS.md has the figures), and with the visibility term
// below (kHiddenSharePerBoundary) over 99.5% on random rooms. (The help states it too:
// kCutCriterionNames, evaluator.h.)
constexpr double kTotalFactor = 1.6;

// Where a point sees few shadow boundaries, a first-order estimate of a cluster whose
// representative is visible errs by a small part of its upper minus lower bound (its
// error is second order; measured on the Cornell box and the emitter, a median of
// 0.12-0.2 of it), but where many clusters are split by shadows (the church) a visible
// representative often belongs to a partly hidden cluster, and the error can exceed that
// spread. So the spread of such a node is scaled by kSmoothSpreadPerBoundary times the
// point's boundary rate (the share of its refined clusters whose two children's
// representatives disagreed about visibility), kept within [kSmoothSpreadMin, 1].
constexpr double kSmoothSpreadPerBoundary = 7.0;
constexpr double kSmoothSpreadMin = 0.5;

// A visible representative does not make its cluster unoccluded: where part of the
// cluster is hidden its estimate is too high by that part's light, and a hidden
// representative's cluster is too low by its visible part. These errors are not the
// estimate's (first-order estimates err by 0.007% of the pixel in sum) but the sampling of
// visibility by one ray per cluster; they cancel on average and their net is what puts
// pixels over 2% in rooms whose lights sit among occluders (measured per cut node on a
// random room, scripts/gen_random_room.py: visible-representative clusters +2.35% of the
// pixel, hidden-representative ones -2.50%; docs/LIGHTCUTS.md). The ray samples a cluster
// whose visible share is v as a coin of probability v: its error has a variance of v(1 - v)
// times the cluster's unshadowed light squared. Two representatives disagree with
// probability 2v(1 - v), so half the point's boundary rate (how often refining split a
// cluster into a visible and a hidden half) stands for v(1 - v): the rate over the
// refinements of clusters that are not clear, the only ones this term counts (a clear
// cluster's children cannot disagree), and of the node's size (kSizeClasses, below).
// Counted over all refinements, a point whose clear clusters were refined hundreds of times
// priced the few partly hidden ones near zero: a library's ceiling (scripts/gen_library.py)
// saw a window's small clusters straddle a shelf's edge at a rate of 0.5%, and 1.8% of its
// pixels were over 2% (0.25% now; the 100k-light room pays 17% more rays, the interiors of
// the benchmark nothing: their clear clusters are few; docs/LIGHTCUTS.md, "The coin's
// rate"). A visible node whose sibling agreed with it adds, in square, its estimate squared
// times that, and so does a hidden node its unshadowed estimate (as well as its upper
// bound), scaled so that the criterion's 1.6 (kTotalFactor) root-sum-square holds 2.576
// standard deviations, where 99% of a normal error lies: (1.6 x 2.576)^2 / 2 = 8.5. (It was
// 4, chosen on random rooms; a lattice, scripts/gen_pergola.py, whose clusters are all
// partly hidden, kept 1.8% of pixels over 2% with full cuts. docs/LIGHTCUTS.md, "One coin
// for both sides".)
constexpr double kVisibilityConfidence = 2.576;
constexpr double kHiddenSharePerBoundary =
    kTotalFactor * kVisibilityConfidence * kTotalFactor * kVisibilityConfidence / 2;

// The coin's rate by the cluster's size. How often a refinement splits a cluster into a
// visible and a hidden half grows with the cluster: in the church at 64 x 64, 3% for
// clusters of 2-3 lights, 6% of 4-7, 11% of 8-15, 17% of 16-31, 20-26% up to 255 and 33-46%
// up to 2,047. The nodes a cut ends with are the small ones (in the church, weighted by
// their coins, of 2-4 lights), so the point's rate over all its refinements overstated
// their v(1 - v) twice over, and the cut refined on for it. Each node's coin now takes the
// rate of the refinements of its own size class (the log2 of its light count) at the point,
// pooled with the larger classes, then the smaller, until kCoinMinRefinements refinements
// back it (a class with few samples borrows the nearest larger ones', whose rates are
// higher), but not less than kCoinRateFloor of the rate over all its refinements: the coin
// takes the nodes' errors for independent, and where one edge crosses a row of small
// clusters (the backs of a theatre's rows of seats) they share a sign; with the size class's
// rate alone an unseen theatre went from 0.006% to 0.21% of pixels over 2%, in streaks under
// the rows, and with the floor it stays at 0.006%. The church's full cuts send 10% fewer
// rays, the benchmark's other interiors 6-9%, the 100k-light room the same (its rates vary
// little with size); no unseen scene has more pixels over 2% than 0.3% (docs/LIGHTCUTS.md,
// "The coin's rate by size").
constexpr int kSizeClasses = detail::kCoinSizeClasses;
constexpr uint32_t kCoinMinRefinements = 16;
constexpr double kCoinRateFloor = 0.5;
constexpr uint32_t kCoinRatesEvery = 8;
inline int sizeClass(uint32_t lights) { return std::min(kSizeClasses - 1, int(std::bit_width(lights)) - 1); }

// The coins of a cut's nodes (CutNode::hideable) summed by size class, each class's times
// its rate at the point (kSizeClasses), kept as nodes come and go. The rates are pooled
// afresh, in one pass over prefix sums, once the refinements counted have grown by
// kCoinRatesEvery and by an eighth since the last time: the criterion asks for the sum at
// every step near the end, and pooling at each of them cost the church a tenth of its
// cut's instructions.
class VisibilityCoins {
 public:
  // A refinement of a cluster of `lights` that was not clear, and whether its children's
  // representatives disagreed.
  void refined(uint32_t lights, bool split) {
    const int c = sizeClass(lights);
    ++tested_[c];
    split_[c] += split;
    ++refinements_;
  }
  // A node's coin comes (positive) or goes (negative).
  void add(uint32_t lights, double hideable) {
    const int c = sizeClass(lights);
    const double next = std::max(0.0, hideable_[c] + hideable);
    sum_ += rate_[c] * (next - hideable_[c]);
    hideable_[c] = next;
  }
  double sum() {
    if (refinements_ >= nextRates_) {
      nextRates_ = refinements_ + std::max(kCoinRatesEvery, refinements_ / 8);
      detail::coinRatesBySize(tested_, split_, kCoinMinRefinements, kCoinRateFloor, rate_);
      sum_ = 0;
      for (int c = 0; c < kSizeClasses; ++c) sum_ += rate_[c] * hideable_[c];
    }
    return sum_;
  }

 private:
  double hideable_[kSizeClasses] = {}, rate_[kSizeClasses] = {};
  uint32_t tested_[kSizeClasses] = {}, split_[kSizeClasses] = {};
  double sum_ = 0;
  uint32_t refinements_ = 0, nextRates_ = 0;  // refinements counted; when to pool again
};

// Second samples (kSecondSampleShare, evaluator.h): a cluster whose representative is
// visible and whose estimate holds more than that share of the cut's error limit gets a
// second sample of its visibility before the cut may stop: the representative of its other
// child, one ray (refining the cluster later casts it again; few are refined: 334 of the
// library's 73k second samples found their light hidden).
// Where that light is hidden the cluster is partly hidden, and it is counted as a node on a
// shadow boundary (its whole upper bound as its spread, no coin), so the cut goes on. The
// coin counts such errors by the point's boundary rate, as errors of random sign; but where
// one edge runs along a row of clusters every representative on their paths can lie on its
// visible side, no refinement splits, and each cluster keeps its hidden part's light, all of
// one sign (a shelf's top across a window panel seen from a library's ceiling,
// scripts/gen_library.py: 25-67% too much light in a dozen clusters of a failing point). A
// quarter: few nodes are that bright once the cut is near its end (the 100k-light room has
// none, the interiors a few per point), and one of them half hidden is an eighth of the
// limit. (docs/LIGHTCUTS.md, "A second sample for bright clusters".)

// A recorded cut marks the spot clusters it estimated by their exact sums (CutRecord::summed),
// and the points between samples sum them too: a cone's step makes the representative a
// 0-or-all sample there. Those walks cost a fifth to a third of a render where spots are
// many, and most summed nodes are dim; so the dimmest are left unmarked, as long as their
// larger of representative's estimate and exact sum at the sample (what either estimate
// can be off by) adds up to at most this share of the cut's error limit: an eighth of the
// error budget (a group probe's is half, reconstruction.h). A quarter left a bias of
// -0.46% over an unseen theatre's stage (an eighth -0.29%, everything summed -0.14%); a
// random room of 3,000 spots: 272.2 rays per point before summing, 303.5 with every node
// summed, 292.0 with this (docs/LIGHTCUTS.md, "Spot clusters the samples summed").
constexpr float kUnsummedShare = 0.125f;

// Clusters of fewer lights are refined rather than probed: up to eight corner rays cost
// more than refining a small cluster does.
constexpr uint32_t kProbeMinLights = 16;

// Clusters of fewer lights are refined with their rays rather than tested for being clear
// (Visibility::boxClear): refining a small cluster costs less than the test often does.
constexpr uint32_t kClearMinLights = 16;
// A point stops testing once its failed tests exceed kClearGraceFailures plus
// kClearFailuresPerSuccess per success: where surfaces stand near most clusters (a church's
// columns and vaults) tests rarely succeed, and each costs about what a ray does; where
// they succeed, it is mostly on the small clusters tested after the large ones failed.
// Measured (issue 21, --stats clear_tests): the Cornell box and the 100k-light room pass 17%
// of their tests, the church 0.15%.
constexpr uint32_t kClearGraceFailures = 48;
constexpr uint32_t kClearFailuresPerSuccess = 8;

// A small cluster (kExactSumMaxLights, exact_sum.h) whose representative contributes
// nothing at the point (it faces away, lies behind the surface's horizon or outside its
// cone: no shadow ray, "untested") keeps an estimate of 0 while the cut is refined, and ends
// with its exact unshadowed sum U times one visibility: either way the truth and the
// estimate lie in [0, U], so U bounds its error as its upper bound over the box does, and
// often far below it (half its lights face away). When such a node comes to the top of the
// heap, U is computed (the walk the end would make, kept for it) and the node goes back with
// U as its bound and spread instead of being refined. Along the luminous torus's silhouette,
// clusters of 2-4 lights each held their whole upper bound; full cuts there send 30% fewer
// rays (docs/LIGHTCUTS.md, "Clusters behind the horizon"). Only untested clusters: for a
// hidden representative the estimate is 0 and the error one-sided, and U in place of the
// bound put an unseen patio from 0.68% to 4.7% of pixels over 2% (the criterion's
// root-sum-square counts on errors of mixed signs). Not in recorded cuts: a point between
// reconstruction samples estimates an untested node by its representative, 0
// (reconstruction.h), so the samples refine them as before (left whole, they put 18% of the
// dense luminous object's pixels over 2% at 512²).

// Whether the segment p + t dir, t in [0, tMax], meets the box [lo, hi] (slabs; a zero
// component of dir leaves its slab's test to p's own coordinate).
inline bool segmentMeetsBox(const Vec3& p, const Vec3& dir, float tMax, const Vec3& lo, const Vec3& hi) {
  float t0 = 0, t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    const float inv = 1 / dir[a];
    float ta = (lo[a] - p[a]) * inv, tb = (hi[a] - p[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// What a representative's shadow ray found (recorded for reconstruction cuts) and, when
// asked for, what stopped it (for the visibility probes).
struct ShadowResult {
  CutVisibility found = CutVisibility::Untested;
  int blocker = Visibility::kVisible;
  float tHit = 0;
  // The luminance of M * G before the ray: what a hidden representative's cluster is
  // estimated to hold, per unit intensity, if it were visible (kHiddenSharePerBoundary).
  float unshadowed = 0;
};

// M * G * V of one light per unit intensity (one shadow ray when the rest is non-zero).
// clear: its visibility is known to be 1 (a clear cluster's light, Visibility::boxClear):
// no ray, and recorded as visible.
inline Color shadowedUnit(const Light& l, const LightGroup& g, const ShadingPoint& sp, Visibility& vis,
                          EvalStats& stats, ShadowResult& res, bool wantBlocker = false, bool clear = false) {
  Color mg;
  Vec3 wi;
  float dist;
  res = ShadowResult{};
  if (!lightContribution(l, g, sp, mg, wi, dist)) return Color(0);
  res.unshadowed = luminance(mg);
  if (clear) {
    res.found = CutVisibility::Visible;
    return mg;
  }
  ++stats.shadowRays;
  Color v = wantBlocker ? vis.trace(wi, dist, res.blocker, res.tHit) : vis(wi, dist);
  res.found = isBlack(v) ? CutVisibility::Occluded
              : (v.x == 1 && v.y == 1 && v.z == 1) ? CutVisibility::Visible
                                                    : CutVisibility::Partial;
  stats.occludedRays += res.found == CutVisibility::Occluded;
  return mg * v;
}

class BruteForce final : public LightEvaluator {
 public:
  explicit BruteForce(const LightSet& lights) : lights_(lights) {}
  EvalResult evaluate(const ShadingPoint& sp, Visibility& vis, EvalStats& stats) const override {
    // Summed in double: over millions of lights a float sum drops the small terms (each
    // below half an ulp of the running sum is lost); at 8.1M VPLs behind a 256-light panel
    // brute force came out up to 8% low.
    Vec3d sum;
    ShadowResult res;
    for (const Light& l : lights_.lights)
      sum += shadowedUnit(l, lights_.groups[l.group], sp, vis, stats, res) * l.intensity;
    uint32_t n = uint32_t(lights_.lights.size());
    stats.recordCut(n);
    return {sum.toFloat(), n};
  }
  Method method() const override { return Method::Brute; }

 private:
  const LightSet& lights_;
};

class Lightcuts final : public LightEvaluator {
 public:
  Lightcuts(const LightSet& lights, const LightForest& forest, const CutOptions& o)
      : lights_(lights), forest_(forest), opt_(o) {}

  // Nodes of the cut live in `nodes` (appended, never moved); the max-heap holds 64-bit
  // keys, the bound's float bits over the node's index (a positive float's bits order as
  // the float does), so sifting compares integers and moves 8 bytes.
  struct CutNode {
    uint32_t tree, node;
    Color unit;      // representative's M*G*V per unit intensity
    Color estimate;  // unit * cluster intensity
    float spread;    // error scale used by the total criterion (see below)
    float lower, upper;   // luminance of the unshadowed bounds (first-order candidates)
    ShadowResult shadow;  // what the representative's shadow ray found
    // The node's children, representative and light count, copied from its LightNode so
    // that refining it reads only its children's cache lines, not its own again, and its
    // children's preorder positions (for the recorded cut).
    NodeRef left, right;
    uint32_t rep, lights, pre, rightPre;  // pre: its own (the left child's is pre + 1)
    bool firstOrder;  // takes the first-order estimate (estimate.h) if it ends in the cut
    bool scaled;      // its spread is scaled by the boundary rate (kSmoothSpreadPerBoundary)
    bool clear;       // no surface can hide any of its lights (Visibility::boxClear)
    float hideable;   // its coin: the luminance squared of its estimate (visible) or of its
                      // unshadowed estimate (hidden), in VisibilityCoins
    uint32_t blocker;  // the hint for its boxClear test
    int32_t exact;     // untested and small: its index in `exacts` once its U is known, else -1
  };

  static uint64_t heapKey(float bound, uint32_t index) {
    uint32_t bits;
    std::memcpy(&bits, &bound, sizeof bits);
    return uint64_t(bits) << 32 | index;
  }
  static float keyBound(uint64_t key) {
    uint32_t bits = uint32_t(key >> 32);
    float b;
    std::memcpy(&b, &bits, sizeof b);
    return b;
  }
  // A 4-ary heap: half the levels of a binary one, and a node's four children share a
  // cache line; the largest child is picked without branches.
  static void heapPush(std::vector<uint64_t>& h, uint64_t key) {
    size_t i = h.size();
    h.push_back(key);
    while (i > 0) {
      size_t parent = (i - 1) / 4;
      if (h[parent] >= key) break;
      h[i] = h[parent];
      i = parent;
    }
    h[i] = key;
  }
  static void heapPop(std::vector<uint64_t>& h) {
    uint64_t key = h.back();
    h.pop_back();
    const size_t n = h.size();
    if (n == 0) return;
    uint64_t* d = h.data();
    size_t i = 0;
    for (;;) {
      size_t c = 4 * i + 1;
      if (c >= n) break;
      size_t best = c;
      uint64_t bv = d[c];
      if (c + 3 < n) {
        uint64_t v1 = d[c + 1], v2 = d[c + 2], v3 = d[c + 3];
        size_t b01 = v1 > bv ? c + 1 : c;
        uint64_t m01 = v1 > bv ? v1 : bv;
        size_t b23 = v3 > v2 ? c + 3 : c + 2;
        uint64_t m23 = v3 > v2 ? v3 : v2;
        best = m23 > m01 ? b23 : b01;
        bv = m23 > m01 ? m23 : m01;
      } else {
        for (size_t k = c + 1; k < n; ++k)
          if (d[k] > bv) bv = d[best = k];
      }
      if (bv <= key) break;
      d[i] = bv;
      i = best;
    }
    d[i] = key;
  }

  EvalResult evaluate(const ShadingPoint& sp, Visibility& vis, EvalStats& stats) const override {
    return cut(sp, vis, stats, nullptr);
  }
  bool supportsReconstruction() const override { return true; }
  EvalResult evaluateRecorded(const ShadingPoint& sp, Visibility& vis, EvalStats& stats,
                              CutRecord& record) const override {
    return cut(sp, vis, stats, &record);
  }
  void mergeSamples(const CutRecord* const* samples, int count, MergedCut& out) const override {
    mergeCuts(lights_, forest_, samples, count, out);
  }
  EvalResult reconstruct(const ShadingPoint& sp, Visibility& vis, EvalStats& stats,
                         const MergedCut& merged) const override {
    ReconstructionResult r = evaluateMergedCut(lights_, merged, sp, vis, stats, groupProbeShare(opt_.errorRatio),
                                               refutingProbeShare(opt_.errorRatio));
    return {r.radiance, r.cutSize};
  }

  // The lightcut at sp; with `record`, its nodes are also written there.
  EvalResult cut(const ShadingPoint& sp, Visibility& vis, EvalStats& stats, CutRecord* record) const {
    static thread_local std::vector<Recorded> recorded;
    recorded.clear();
    static thread_local std::vector<uint64_t> heap;
    static thread_local std::vector<CutNode> nodes;
    static thread_local std::vector<ExactSum> exacts;  // the U of untested small clusters
    // Per node of `nodes`: the luminance of its estimate while it may take a second sample
    // (visible representative, a coin, not sampled twice), else -1. secondSamples scans
    // the heap through these 4 bytes, not the nodes (a scan per cut read ~700 of them: 9%
    // of the cut loop's own time, perf on 1M VPLs).
    static thread_local std::vector<float> secondLum;
    heap.clear();
    nodes.clear();
    secondLum.clear();
    exacts.clear();
    BoundFrames frames(sp);
    const PairFrames pairFrames(sp, frames);
    // The cut's estimate, in double: refinement subtracts a node's estimate and adds its
    // children's thousands of times, and the stopping rule compares against it.
    Vec3d total;
    uint32_t cutSize = 0;
    // Sums of the squared spreads of the nodes in the heap: those scaled by the boundary
    // rate, and the others; and their coins (kHiddenSharePerBoundary).
    double sumSq = 0, sumScaled = 0;
    VisibilityCoins coins;
    // The boundary rate's counts (the coins count the refinements of clusters that were not
    // clear, whose children can disagree, by size).
    uint32_t refinedTested = 0, refinedSplit = 0;
    const bool rss = opt_.criterion == CutCriterion::Total;
    const bool firstOrder = opt_.estimator == Estimator::FirstOrder;
    const bool probes = opt_.visibilityProbes;
    const bool clearTests = opt_.clearClusters && sp.clearTests;
    uint32_t clearFailures = 0, clearSuccesses = 0;

    // Inner nodes pushed by the last refinement (tree, children): their children's lights
    // are prefetched after the next one (below).
    struct Pushed {
      uint32_t tree;
      NodeRef left, right;
    };
    Pushed pending[2], fresh[2];
    uint32_t pendingCount = 0, freshCount = 0;
    // Adds a node to the cut: its estimate to the total, and to the heap unless exact.
    auto record1 = [&](uint32_t t, NodeRef ni, uint32_t pre, CutVisibility found, bool fo, float factor = 1) {
      recorded.push_back(Recorded{uint64_t(t) << 32 | CutRecord::pack(pre, found, fo), factor, ni});
    };
    // Node ni, at preorder position pre.
    // clear: the node's parent was clear (Visibility::boxClear), and so is the node;
    // blocker: what stopped the last such test on its way down (a hint for its own);
    // bounds: its bounds when they were computed with its sibling's (clusterBoundsPair).
    auto addNode = [&](uint32_t t, NodeRef ni, uint32_t pre, const Color& unit, const ShadowResult& shadow,
                       bool boundary = false, bool clear = false, uint32_t blocker = Visibility::kNoHint,
                       const ChildBounds* bounds = nullptr) {
      const CutVisibility found = shadow.found;
      const LightTree& tree = forest_.trees[t];
      if (isLeafRef(ni)) {
        total += unit * leafIntensity(lights_.lights[leafLight(ni)]);
        ++cutSize;
        if (record) record1(t, ni, pre, found, false);
        return;
      }
      const LightNode& n = tree.nodes[ni];
      Color est = unit * n.intensity;
      total += est;
      ++cutSize;
      ++stats.boundsEvaluated;
      // The total criterion adds up how far each estimate may be off: a cluster whose
      // representative is visible (and whose sibling's was: not on a shadow boundary,
      // `boundary`) is assumed unoccluded, so its estimate is within the upper minus the
      // lower bound of its unshadowed light; otherwise (or when it is partly hidden, which
      // the per-node rule still bounds) within the upper bound.
      bool visible = (rss || firstOrder) && !isBlack(unit);
      Color lower, upper;
      bool smooth = false;
      if (bounds) {
        upper = bounds->upper;
        if (visible) {
          lower = bounds->lower;
          smooth = bounds->smooth;
        }
      } else {
        // A tree that mixes groups bounds from below with their lower envelope (LightTree).
        upper = clusterBounds(n, tree.type, tree.bound, sp, frames, visible ? &lower : nullptr, &smooth,
                              tree.mixedGroups ? &tree.boundLow : nullptr);
      }
      float b = luminance(upper);
      if (b > 0) {
        // A node in the heap may be refined next: fetch its children while we work (a
        // leaf child: its light).
        const NodeRef left = n.left(ni), right = n.right(ni);
        for (NodeRef c : {left, right})
          __builtin_prefetch(isLeafRef(c) ? static_cast<const void*>(&lights_.lights[leafLight(c)])
                                          : static_cast<const void*>(&tree.nodes[c]));
        if (freshCount < 2) fresh[freshCount++] = {t, left, right};
        const float lo = luminance(lower);
        // A hidden representative's spread stays its whole upper bound. (Counting its
        // cluster's visible part as the other side of the visibility coin instead of that
        // bound saved 7-11% of the rays but put a room lit through blinds,
        // scripts/gen_blinds.py, from 1.44% to 1.68% of pixels over 2%; it is counted as
        // well as the bound, below. docs/LIGHTCUTS.md.)
        float spread = visible && !boundary ? std::max(0.0f, b - lo) : b;
        // Where the contribution is smooth over the cluster and its representative is
        // unoccluded, the node takes the first-order estimate (estimate.h) if it is still
        // in the cut at the end (most nodes are refined before that). Its spread, upper
        // minus lower, is scaled by the boundary rate when the criterion is tested: the
        // estimate's own error is second order, a partly hidden cluster's is not.
        const bool fo = firstOrder && smooth && found == CutVisibility::Visible;
        // Its moments are read at the end if it stays in the cut: a miss there cost 17% of
        // the cut loop (perf, 100k point lights).
        if (fo) __builtin_prefetch(&tree.moments[ni]);
        const bool scaled = rss && fo && !boundary;
        (scaled ? sumScaled : sumSq) += double(spread) * spread;
        // The visibility coin, both sides: a visible representative's cluster (its sibling's
        // was visible too) may be partly hidden, a hidden one's partly visible, and the
        // error is that part of its unshadowed light. The hidden side is an error of one
        // sign on each of hundreds of nodes where a fine screen splits every cluster
        // (scripts/gen_lattice.py, gen_pergola.py): its upper bound alone, in the root-sum-
        // square, left 0.65-0.72% of their pixels over 2% with full cuts (docs/LIGHTCUTS.md,
        // "The hidden side of the coin"). Its unshadowed estimate is the representative's
        // M * G luminance times the cluster's (exact for grey lights).
        float le = 0;
        if (rss && !clear) {
          if (visible && !boundary) le = luminance(est);
          else if (found == CutVisibility::Occluded) le = shadow.unshadowed * luminance(n.intensity);
        }
        const float hideable = le * le;
        coins.add(n.lights(), hideable);
        // The heap orders nodes by what their estimates may be off by: a clear cluster's
        // estimate and its light both lie within its lower and upper bounds, so its spread;
        // any other's by its upper bound (it may be partly hidden, whatever its
        // representative found). Ordered by their upper bounds, clear clusters were refined
        // as if they could hide their light: 484 of the 100k-light room's 896 refinements a
        // point, 326 now (docs/LIGHTCUTS.md, "Clear clusters ordered by their spreads").
        // Not in recorded cuts: a cluster clear from the sample may be partly hidden from the
        // points between samples that use its cut, where one ray decides its visibility, and
        // only its upper bound limits that error (the Cornell box at 64 x 64 in cells of 4:
        // 0.29% -> 1.34% of pixels over 2%, and 1.37% with a ray for every node).
        heapPush(heap, heapKey(clear && !record ? spread : b, uint32_t(nodes.size())));
        nodes.push_back(CutNode{t, ni, unit, est, spread, lo, b, shadow, left, right, n.rep, n.lights(),
                                pre, n.rightPre(pre), fo, scaled, clear, hideable, blocker, -1});
        secondLum.push_back(hideable > 0 && found == CutVisibility::Visible ? luminance(est) : -1.0f);
      } else if (record) {
        record1(t, ni, pre, found, false);
      }
    };

    // Second samples for the bright clusters in the cut whose visible representative stands
    // for them alone (kSecondSampleShare); true when one was found partly hidden and its
    // spread raised to its upper bound (the criterion must be tested again).
    auto secondSamples = [&](float limit) {
      bool raised = false;
      const float least = kSecondSampleShare * limit;
      for (uint64_t key : heap) {
        if (!(secondLum[uint32_t(key)] > least)) continue;
        CutNode& cn = nodes[uint32_t(key)];
        secondLum[uint32_t(key)] = -1;  // given its second sample
        const LightTree& tree = forest_.trees[cn.tree];
        const uint32_t other = tree.repOf(tree.repOf(cn.left) == cn.rep ? cn.right : cn.left);
        if (other == cn.rep) continue;
        ShadowResult second;
        const Light& l = lights_.lights[other];
        shadowedUnit(l, lights_.groups[l.group], sp, vis, stats, second);
        ++stats.secondSamples;
        if (second.found != CutVisibility::Occluded && second.found != CutVisibility::Partial) continue;
        ++stats.secondSamplesHidden;
        double& sum = cn.scaled ? sumScaled : sumSq;
        sum = std::max(0.0, sum - double(cn.spread) * cn.spread);
        coins.add(cn.lights, -double(cn.hideable));
        cn.hideable = 0;
        cn.scaled = false;
        cn.spread = cn.upper;
        sumSq += double(cn.spread) * cn.spread;
        raised = true;
      }
      return raised;
    };

    uint32_t cutRoots = 0;
    for (uint32_t t = 0; t < forest_.trees.size(); ++t) {
      const LightTree& tree = forest_.trees[t];
      if (tree.empty()) continue;
      ShadowResult shadow;
      const Light& rootRep = lights_.lights[tree.repOf(tree.root)];
      Color unit = shadowedUnit(rootRep, lights_.groups[rootRep.group], sp, vis, stats, shadow,
                                probes && tree.lightCount(tree.root) >= kProbeMinLights);
      addNode(t, tree.root, 0, unit, shadow);
      ++cutRoots;
    }
    // The budget grows by one node per tree after the first: a forest of more trees than
    // --max-cut still refines its large trees. Stopping at the roots left a 15,000-light
    // tree as one representative (errors of 1,000% beside 15,000 one-spot trees).
    const uint32_t maxCut = uint32_t(opt_.maxCut) + std::max(cutRoots, 1u) - 1;
    const float eps = std::max(opt_.errorRatio, sp.minError);
    const double rssFactor2 = kTotalFactor * kTotalFactor;
    while (!heap.empty()) {
      // Weber's law has a floor: below errorFloor (set by the renderer from the image's
      // mean) the cut is held to an absolute error, as the image metric's floor does.
      float limit = float(eps * std::max(luminance(total), double(sp.errorFloor)));
      const uint64_t top = heap.front();
      if (keyBound(top) <= limit) {
        if (!rss) break;
        const double rate = double(refinedSplit) / std::max(1u, refinedTested);
        const double w = std::clamp(kSmoothSpreadPerBoundary * rate, kSmoothSpreadMin, 1.0);
        auto holds = [&] {
          return sumSq + w * w * sumScaled + kHiddenSharePerBoundary * coins.sum() <=
                 rssFactor2 * double(limit) * limit;
        };
        if (holds() && !(opt_.secondSamples && secondSamples(limit) && !holds())) break;
      }
      // Out of budget with the bound not met: the cut's error may exceed --error (counted,
      // and the render warns).
      if (cutSize >= maxCut) {
        ++stats.cutsAtMaxCut;
        break;
      }
      heapPop(heap);
      CutNode& popped = nodes[uint32_t(top)];
      if (!record && popped.shadow.found == CutVisibility::Untested && popped.exact < 0 &&
          popped.lights <= kExactSumMaxLights) {
        // Untested and small: its exact unshadowed sum bounds its error (above).
        popped.exact = int32_t(exacts.size());
        exacts.push_back(unshadowedSum(lights_, forest_.trees[popped.tree], popped.node, sp));
        const float u = luminance(exacts.back().sum);
        if (u < popped.spread) {
          sumSq = std::max(0.0, sumSq - double(popped.spread) * popped.spread) + double(u) * u;
          popped.spread = u;
          heapPush(heap, heapKey(u, uint32_t(top)));
          continue;
        }
      }
      // Read in place (a copy was 1.2% of the room's cut): this refinement adds two nodes,
      // so room for them is made first and `nodes` does not move under the reference.
      if (nodes.capacity() < nodes.size() + 2) nodes.reserve(2 * nodes.capacity() + 2);
      const CutNode& cn = nodes[uint32_t(top)];
      double& sum = cn.scaled ? sumScaled : sumSq;
      sum = std::max(0.0, sum - double(cn.spread) * cn.spread);
      coins.add(cn.lights, -double(cn.hideable));
      const LightTree& tree = forest_.trees[cn.tree];
      if (probes && cn.shadow.blocker >= 0 && cn.lights >= kProbeMinLights &&
          hiddenCluster(tree.nodes[cn.node], tree.type, sp, cn.shadow, vis, stats)) {
        // Its representative is hidden, and so is the whole cluster: it stays in the cut,
        // exactly 0, instead of being refined down to its lights.
        ++stats.hiddenClusters;
        if (record) record1(cn.tree, cn.node, cn.pre, CutVisibility::Occluded, false);
        continue;
      }
      total -= cn.estimate;
      --cutSize;
      // A cluster whose representative is visible may be visible as a whole: then its
      // refinement casts no rays, and its sub-clusters are clear too. Tested when it is
      // about to be refined: a cluster that stays in the cut would save nothing.
      bool cnClear = cn.clear;
      uint32_t blocker = cn.blocker;
      if (!cnClear && clearTests && cn.shadow.found == CutVisibility::Visible && tree.type != LightType::Directional &&
          cn.lights >= kClearMinLights && clearFailures < kClearGraceFailures + kClearFailuresPerSuccess * clearSuccesses) {
        ++stats.clearTests;
        const LightNode& pn = tree.nodes[cn.node];
        cnClear = vis.boxClear(pn.lo, pn.hi, blocker);
        stats.clearedClusters += cnClear;
        (cnClear ? clearSuccesses : clearFailures) += 1;
      }
      ShadowResult shadows[2];
      Color units[2];
      bool boundary = false;
      for (uint32_t k = 0; k < 2; ++k) {
        const NodeRef c = k ? cn.right : cn.left;
        const uint32_t rep = tree.repOf(c);
        // The child that shares the parent's representative reuses its shadow ray; in a
        // clear cluster no child needs one. Only clusters that may be probed need to know
        // what hid their representative.
        if (rep == cn.rep) {
          shadows[k] = cn.shadow;
          units[k] = cn.unit;
        } else {
          units[k] = shadowedUnit(lights_.lights[rep], lights_.groups[lights_.lights[rep].group], sp, vis, stats,
                                  shadows[k], probes && tree.lightCount(c) >= kProbeMinLights, cnClear);
        }
      }
      // A shadow boundary: one child's representative is hidden, the other's not (never in
      // a clear cluster, whose refinements count in the boundary rate as their rays would
      // have: the rate's constants were measured with them counted).
      if (shadows[0].found != CutVisibility::Untested && shadows[1].found != CutVisibility::Untested) {
        auto hidden = [](CutVisibility v) { return v == CutVisibility::Occluded || v == CutVisibility::Partial; };
        boundary = hidden(shadows[0].found) != hidden(shadows[1].found);
        ++refinedTested;
        refinedSplit += boundary;
        if (!cnClear) coins.refined(cn.lights, boundary);
      }
      // Two inner children are bounded together (bounds_pair.h): the same bounds bit for
      // bit, and the cut loop 7-9% faster (docs/BENCHMARKS.md).
      ChildBounds pair[2];
      const bool paired =
          !isLeafRef(cn.left) && !isLeafRef(cn.right) && boundsPairApplies(tree.type, tree.mixedGroups);
      if (paired) clusterBoundsPair(tree.nodes[cn.left], tree.nodes[cn.right], tree.type, tree.bound, pairFrames, pair);
      addNode(cn.tree, cn.left, LightNode::leftPre(cn.pre), units[0], shadows[0], boundary, cnClear, blocker,
              paired ? &pair[0] : nullptr);
      addNode(cn.tree, cn.right, cn.rightPre, units[1], shadows[1], boundary, cnClear, blocker,
              paired ? &pair[1] : nullptr);
      // A second stage of prefetching: the children of the nodes pushed one refinement ago
      // have arrived (addNode fetched them); fetch their representatives' lights, which the
      // next refinement's shadow ray reads (a miss on the light was half of
      // lightContribution's time, perf on 100k point lights).
      for (uint32_t k = 0; k < pendingCount; ++k) {
        const LightTree& ptree = forest_.trees[pending[k].tree];
        for (NodeRef c : {pending[k].left, pending[k].right})
          if (!isLeafRef(c)) __builtin_prefetch(&lights_.lights[ptree.nodes[c].rep]);
      }
      pendingCount = freshCount;
      for (uint32_t k = 0; k < freshCount; ++k) pending[k] = fresh[k];
      freshCount = 0;
    }
    // The first-order estimates of the clusters left in the cut, kept within their bounds;
    // their ratio to the representative's is what a reconstruction borrows. Their nodes,
    // moments and lights are fetched first, all at once: read one by one, each was a cache
    // miss (perf: 13% of the cut loop on 100k point lights).
    if (firstOrder) {
      for (uint64_t key : heap) {
        const CutNode& cn = nodes[uint32_t(key)];
        if (!cn.firstOrder) continue;
        const LightTree& tree = forest_.trees[cn.tree];
        __builtin_prefetch(&tree.nodes[cn.node]);
        __builtin_prefetch(&tree.moments[cn.node]);
        __builtin_prefetch(&lights_.lights[cn.rep]);
      }
    }
    // The spot nodes estimated by their exact sums: the larger of their representative's
    // estimate and their sum, and their place in `recorded` (kUnsummedShare).
    static thread_local std::vector<std::pair<float, uint32_t>> summedAt;
    summedAt.clear();
    for (uint64_t key : heap) {
      const CutNode& cn = nodes[uint32_t(key)];
      float factor = 1;
      bool summed = false;  // a spot cluster estimated by its exact sum (CutRecord::summed)
      const LightTree& ctree = forest_.trees[cn.tree];
      if (firstOrder && !cn.firstOrder && cn.lower <= 0 && ctree.lightCount(cn.node) <= kExactSumMaxLights &&
          cn.shadow.found != CutVisibility::Occluded && cn.shadow.found != CutVisibility::Partial) {
        // A small cluster across the surface's horizon (no lower bound): its exact
        // unshadowed sum, times the visibility of its representative or, when that one is
        // behind the surface or outside its cone, of its brightest light.
        const ExactSum sumU = cn.exact >= 0 ? exacts[cn.exact] : unshadowedSum(lights_, ctree, cn.node, sp);
        Color exact = withVisibility(sumU, vis, stats, cn.shadow.found == CutVisibility::Visible);
        float raw = luminance(cn.estimate), le = luminance(exact);
        total += exact;
        total -= cn.estimate;
        if (raw > 0 && le > 0) factor = std::clamp(le / raw, 0.5f, 2.0f);
        summed = ctree.type == LightType::Spot;
        if (summed && record) summedAt.push_back({std::max(raw, luminance(sumU.sum)), uint32_t(recorded.size())});
      } else if (cn.firstOrder) {
        const LightTree& tree = forest_.trees[cn.tree];
        const LightNode& n = tree.nodes[cn.node];
        // A first-order node is never a leaf: its moments are stored.
        const Light& rep = lights_.lights[cn.rep];
        Color fo = vmax(firstOrderUnit(rep, lights_.groups[rep.group], sp,
                                       tree.moments[cn.node], cn.unit) * n.intensity, Color(0));
        float raw = luminance(cn.estimate), lf = luminance(fo);
        if (raw > 0 && lf > 0) {
          float kept = std::clamp(lf, cn.lower, cn.upper);
          fo *= kept / lf;
          total += fo;
          total -= cn.estimate;
          factor = std::clamp(kept / raw, 0.5f, 2.0f);
        }
      }
      // (A summed node's factor goes into `recorded` negated: factors are never 0.)
      if (record) record1(cn.tree, cn.node, cn.pre, cn.shadow.found, cn.firstOrder, summed ? -factor : factor);
    }
    if (record && !summedAt.empty()) {
      // The dimmest summed nodes are left to their representatives (kUnsummedShare).
      std::sort(summedAt.begin(), summedAt.end());
      double budget = double(kUnsummedShare) * eps * luminance(total);
      for (const auto& [u, at] : summedAt) {
        if (u > budget) break;
        budget -= u;
        recorded[at].factor = std::fabs(recorded[at].factor);
      }
    }
    if (record) {
      // The cut: the nodes left in the heap, and the exact ones recorded as they came.
      sortRecorded(recorded);
      record->clear();
      record->valid = true;
      record->point = sp.p;
      record->entries.resize(recorded.size());
      record->factor.resize(recorded.size());
      record->summed.resize(recorded.size());
      record->nodes.resize(recorded.size());
      record->treeBegin.assign(forest_.trees.size() + 1, uint32_t(recorded.size()));
      for (size_t i = recorded.size(); i-- > 0;) {
        record->entries[i] = uint32_t(recorded[i].key);
        record->factor[i] = std::fabs(recorded[i].factor);
        record->summed[i] = recorded[i].factor < 0;
        record->nodes[i] = recorded[i].node;
        record->treeBegin[recorded[i].key >> 32] = uint32_t(i);
      }
      // Trees with no entries begin where the next one does.
      for (size_t t = forest_.trees.size(); t-- > 0;)
        record->treeBegin[t] = std::min(record->treeBegin[t], record->treeBegin[t + 1]);
      record->finish();
    }
    stats.recordCut(cutSize);
    return {vmax(total.toFloat(), Color(0)), cutSize};
  }
  Method method() const override { return Method::Lightcuts; }

 private:
  // Whether the whole cluster is provably hidden from sp: its representative's shadow ray
  // (`rep`) and those toward the corners of its bounding box all meet one convex opaque
  // object, nearer than the box. The directions whose ray meets a convex object within a
  // distance T form a convex cone, so every direction into the box (in the hull of the
  // corners' directions) meets it within the corners' largest distance, nearer than any
  // light of the box: the cluster's visibility is 0, and so is its error. A corner behind
  // the surface (whose ray the surface itself would stop), or blocked by anything else (a
  // wall, glass, a non-convex mesh), means no.
  bool hiddenCluster(const LightNode& n, LightType type, const ShadingPoint& sp, const ShadowResult& rep,
                     Visibility& vis, EvalStats& stats) const {
    if (type == LightType::Directional) return false;
    const float dMin = length(vmax(vmax(n.lo - sp.p, sp.p - n.hi), Vec3(0.0f)));
    if (rep.blocker < 0 || !(rep.tHit < dMin)) return false;
    ++stats.probedClusters;
    Vec3 dirs[8];
    float dists[8];
    int m = 0;
    // A corner whose ray cannot meet the blocker's box before dMin cannot be hidden by it:
    // the probe would fail there, so it fails now, before any ray (a thin upright in front
    // of a wide cluster). The same answers as the rays', for fewer rays. Tested corner by
    // corner as their directions are made: most probes end at the first or second.
    Vec3 blo, bhi;
    const bool boxed = vis.blockerBox(rep.blocker, blo, bhi);
    for (int k = 0; k < 8; ++k) {
      // A flat box has only four distinct corners: the others repeat them.
      if (((k & 1) && n.lo.x == n.hi.x) || ((k & 2) && n.lo.y == n.hi.y) || ((k & 4) && n.lo.z == n.hi.z)) continue;
      Vec3 corner((k & 1) ? n.hi.x : n.lo.x, (k & 2) ? n.hi.y : n.lo.y, (k & 4) ? n.hi.z : n.lo.z);
      Vec3 d = corner - sp.p;
      dists[m] = length(d);
      dirs[m] = d / dists[m];
      if (!(dot(dirs[m], sp.n) > 0)) return false;
      if (boxed && !segmentMeetsBox(sp.p, dirs[m], dMin, blo, bhi)) {
        ++stats.probesRuledOut;
        return false;
      }
      ++m;
    }
    // A blocker whose shape is known (a box, sphere, capped cylinder, square, convex mesh or
    // a mesh's flat face) is asked directly whether it stops every corner's segment: no rays.
    switch (vis.blocksAll(rep.blocker, dirs, m, dMin)) {
      case 0: ++stats.probesRuledOut; return false;
      case 1: return true;
      default: break;
    }
    for (int i = 0; i < m; ++i) {
      const Vec3& wi = dirs[i];
      const float dist = dists[i];
      ++stats.shadowRays;
      ++stats.probeRays;
      int blocker;
      float tHit;
      vis.trace(wi, dist, blocker, tHit);
      if (blocker != rep.blocker || !(tHit < dMin)) return false;
    }
    return true;
  }

  const LightSet& lights_;
  const LightForest& forest_;
  CutOptions opt_;
};

class CourseCuts final : public LightEvaluator {
 public:
  CourseCuts(const LightSet& lights, const LightForest& forest, const CutOptions& o)
      : lights_(lights), forest_(forest), opt_(o) {
    // Trees without the seed's traversal data (agglomerative ones) get it here, once.
    seed_.resize(forest.trees.size());
    owned_.reserve(forest.trees.size());
    for (size_t t = 0; t < forest.trees.size(); ++t) {
      const LightTree& tree = forest.trees[t];
      if (tree.course.size() == tree.nodes.size()) {
        seed_[t] = tree.course.data();
      } else {
        owned_.push_back(courseNodeData(lights, tree));
        seed_[t] = owned_.back().data();
      }
    }
  }

  EvalResult evaluate(const ShadingPoint& sp, Visibility& vis, EvalStats& stats) const override {
    static thread_local std::vector<std::pair<uint32_t, uint32_t>> stack;
    stack.clear();
    Color total(0);
    uint32_t cutSize = 0;
    for (uint32_t t = 0; t < forest_.trees.size(); ++t)
      if (!forest_.trees[t].empty()) stack.emplace_back(t, forest_.trees[t].root);
    // As for lightcuts: one more node per tree after the first.
    const size_t maxCut = size_t(opt_.maxCut) + std::max<size_t>(stack.size(), 1) - 1;
    while (!stack.empty()) {
      auto [t, ni] = stack.back();
      stack.pop_back();
      const LightTree& tree = forest_.trees[t];
      const LightGroup& g = tree.bound;  // the synthetic light's (a leaf uses its own)
      if (!isLeafRef(ni)) {
        const LightNode& n = tree.nodes[ni];
        const CourseNodeData& sd = seed_[t][ni];
        float dist = tree.type == LightType::Directional ? 1.0f : length(sp.p - sd.position);
        if (sd.error > opt_.errorRatio * dist && cutSize + stack.size() + 2 <= maxCut) {
          stack.emplace_back(t, n.left(ni));
          stack.emplace_back(t, n.right(ni));
          continue;
        }
      }
      bool blocked = false;
      Color c = nodeLight(tree, seed_[t], g, ni, sp, vis, stats, blocked);
      if (blocked) {
        // The seed's fallback: a blocked representative (of an inner node: a leaf is never
        // `blocked`) may hide lights that are visible; its two children (one level only)
        // stand in for it.
        const LightNode& n = tree.nodes[ni];
        for (NodeRef k : {n.left(ni), n.right(ni)}) {
          bool unused;
          total += nodeLight(tree, seed_[t], g, k, sp, vis, stats, unused);
        }
        cutSize += 2;
        continue;
      }
      total += c;
      ++cutSize;
    }
    stats.recordCut(cutSize);
    return {total, cutSize};
  }
  Method method() const override { return Method::Course; }

 private:
  // The contribution of a node's light: the light itself at a leaf, the synthetic
  // centroid light otherwise (its visibility measured toward the node's representative
  // light). `blocked` is set when an inner node's light is non-zero but fully occluded.
  Color nodeLight(const LightTree& tree, const CourseNodeData* seed, const LightGroup& g, NodeRef ni,
                  const ShadingPoint& sp, Visibility& vis, EvalStats& stats, bool& blocked) const {
    blocked = false;
    ShadowResult found;
    if (isLeafRef(ni)) {
      const Light& l = lights_.lights[leafLight(ni)];
      return shadowedUnit(l, lights_.groups[l.group], sp, vis, stats, found) * leafIntensity(l);
    }
    const LightNode& n = tree.nodes[ni];
    const CourseNodeData& sd = seed[ni];
    Light syn;
    syn.type = tree.type;
    syn.group = tree.group;
    syn.position = sd.position;
    syn.direction = tree.type == LightType::Directional ? -normalize(sd.position) : sd.direction;
    Color mg;
    Vec3 wi;
    float dist;
    if (!lightContribution(syn, g, sp, mg, wi, dist)) return Color(0);
    // The averaged light can lie inside a closed emitter (the centre of a glowing sphere),
    // where every shadow ray toward it is blocked by the emitter itself; its visibility is
    // taken toward the cluster's representative light instead, a point on a real emitter.
    const Light& rep = lights_.lights[n.rep];
    Vec3 repDir = tree.type == LightType::Directional ? -rep.direction : rep.position - sp.p;
    float repDist = tree.type == LightType::Directional ? kInf : length(repDir);
    if (!(repDist > 0)) return mg * n.intensity;
    ++stats.shadowRays;
    Color v = vis(tree.type == LightType::Directional ? repDir : repDir / repDist, repDist);
    blocked = isBlack(v);
    return mg * v * n.intensity;
  }

  const LightSet& lights_;
  const LightForest& forest_;
  CutOptions opt_;
  std::vector<const CourseNodeData*> seed_;  // per tree: its own or owned_'s
  std::vector<std::vector<CourseNodeData>> owned_;
};

}  // namespace

namespace detail {

// One pass over prefix sums: a class's window [begin, end) grows upward (end never moves
// back as the class rises) and, where the classes above hold too few, down to `low`.
void coinRatesBySize(const uint32_t tested[kCoinSizeClasses], const uint32_t split[kCoinSizeClasses],
                     uint32_t minRefinements, double floorShare, double rates[kCoinSizeClasses]) {
  constexpr int n = kCoinSizeClasses;
  uint32_t t[n + 1], s[n + 1];
  t[0] = s[0] = 0;
  for (int c = 0; c < n; ++c) {
    t[c + 1] = t[c] + tested[c];
    s[c + 1] = s[c] + split[c];
  }
  // The highest class from which the classes up to the largest hold enough.
  int low = n;
  while (low > 0 && t[n] - t[low] < minRefinements) --low;
  const double floor = t[n] > 0 ? floorShare * s[n] / t[n] : 0.0;
  for (int c = 0, end = 1; c < n; ++c) {
    end = std::max(end, c + 1);
    while (end < n && t[end] - t[c] < minRefinements) ++end;
    const int begin = t[end] - t[c] < minRefinements ? std::min(c, low) : c;
    const uint32_t count = t[end] - t[begin];
    rates[c] = std::max(floor, count > 0 ? double(s[end] - s[begin]) / count : 0.0);
  }
}

}  // namespace detail

// Tests enough to judge a rate of one in kClearMinLights by.
constexpr uint64_t kClearJudgedTests = 1000;
bool clearTestsPay(uint64_t tests, uint64_t passed) {
  return tests < kClearJudgedTests || passed * kClearMinLights >= tests;
}

std::unique_ptr<LightEvaluator> makeBruteForce(const LightSet& lights) {
  return std::make_unique<BruteForce>(lights);
}

std::unique_ptr<LightEvaluator> makeLightcuts(const LightSet& lights, const LightForest& forest,
                                              const CutOptions& options) {
  return std::make_unique<Lightcuts>(lights, forest, options);
}
std::unique_ptr<LightEvaluator> makeCourseCuts(const LightSet& lights, const LightForest& forest,
                                             const CutOptions& options) {
  return std::make_unique<CourseCuts>(lights, forest, options);
}

}  // namespace lc::lightcuts
