// Light evaluators: the direct light at a shading point from every light of a LightSet,
// computed three ways that share one light model and one exact contribution function.
//   brute      every light, exactly: the reference.
//   lightcuts  Walter et al. 2005: a cut through the light tree chosen per point by a
//              max-heap on the clusters' error upper bounds, refined until every bound is
//              below errorRatio times the current estimate (or maxCut nodes). Two
//              extensions, each with an option to turn it off: clusters are estimated to
//              first order where that is valid (estimate.h), and a cluster whose
//              representative is hidden is first tested for being hidden as a whole
//              (visibility probes, below) instead of being refined down to its lights.
//              Its cuts can be recorded at sparse samples and rebuilt between them
//              (reconstruction cuts, reconstruction.h).
//   seed       the course project's traversal: descend while a node's error radius over
//              its distance exceeds errorRatio; a blocked representative is replaced by its
//              two children (one level, not recursively).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "lightcuts/estimate.h"
#include "lightcuts/eval_stats.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/reconstruction.h"
#include "lightcuts/shading.h"
#include "core/enum_names.h"
#include "core/light.h"

namespace lc::lightcuts {

// Stochastic: stochastic lightcuts (stochastic.cpp), unbiased and noisy.
// Course: the course project's cuts this product grew from ("the seed", docs/SEED.md;
// `--method seed` or `course`).
enum class Method { Brute, Lightcuts, Course, Stochastic };
// Its names (core/enum_names.h: the first of a value its name, then aliases), in the order
// render --method's help lists them; read by the functions below and by the CLI.
inline constexpr EnumName<Method> kMethodNames[] = {
    {Method::Lightcuts, "lightcuts", "Walter et al. 2005"},
    {Method::Course, "seed", "the course project's cuts"},
    {Method::Course, "course"},
    {Method::Stochastic, "stochastic",
     "stochastic lightcuts, Yuksel 2019: unbiased, noisy, no error bound; average with --spp"},
    {Method::Brute, "brute"}};
// Throws lc::Error for another name.
inline Method parseMethod(std::string_view name) { return parseEnum(kMethodNames, name, "method"); }
inline const char* methodName(Method m) { return enumName(kMethodNames, m); }

// When a cut is good enough.
//   Walter: every node's error bound is below errorRatio times the total estimate (Walter
//     et al. 2005). The errors of many nodes near the threshold add up, so the total
//     error is often a few times errorRatio.
//   Total: the same, and also the root-sum-square of the nodes' error spreads is below
//     1.6 x errorRatio times the estimate. A node's spread is its upper bound, or, when
//     its representative is visible and its sibling's was not hidden, its upper minus its
//     lower bound (what the estimate of an unoccluded cluster can be off by), for a
//     first-order estimate scaled down where the point sees few shadow boundaries; a
//     node with a visible representative also counts the part of its cluster that may be
//     hidden, and one with a hidden representative the part that may be visible, in
//     proportion to how often the point's clusters turned out partly hidden
//     (evaluator.cpp, kHiddenSharePerBoundary). The errors of a cut have random signs, so
//     this keeps the total error, not just each node's, near errorRatio.
enum class CutCriterion { Walter, Total };
inline constexpr EnumName<CutCriterion> kCutCriterionNames[] = {
    {CutCriterion::Total, "total",
     "every bound below error x estimate and the root-sum-square of the error spreads below 1.6 x that"},
    {CutCriterion::Walter, "walter", "every bound below error x estimate, as published"}};
// Throws lc::Error for another name.
inline CutCriterion parseCutCriterion(std::string_view name) {
  return parseEnum(kCutCriterionNames, name, "cut criterion");
}
inline const char* cutCriterionName(CutCriterion c) { return enumName(kCutCriterionNames, c); }

// The seed's traversal compares an error radius with the distance to the point, not a
// relative bound, so its --error has its own default; the seed did not publish its value,
// and 0.25 gives the default Cornell box about the cut the seed reported (257 vs 273.6
// lights per pixel).
constexpr float kCourseCutsDefaultError = 0.25f;

// --second-samples: the share of the cut's error limit over which a cluster's estimate gets
// a second sample of its visibility (CutOptions::secondSamples).
constexpr float kSecondSampleShare = 0.25f;

struct CutOptions {
  float errorRatio = 0.02f;  // --error: relative error threshold
  // --max-cut: most nodes in one cut, plus one per tree after the first. Past it a cut stops
  // with its bound unmet (counted: EvalStats::cutsAtMaxCut, and the render warns). 16000:
  // at 4000 (1000 before, Walter's figure) the suite's halls stopped 5-6% of their cuts there
  // and a room lit through blinds 23%, with errors up to 7%; the cuts that reach 4000 end
  // below 16000 (docs/LIGHTCUTS.md, "Cut selection").
  int maxCut = 16000;
  CutCriterion criterion = CutCriterion::Total;
  Estimator estimator = Estimator::FirstOrder;  // --estimator (estimate.h)
  // --visibility-probes: before a cluster of 16 lights or more whose representative is
  // hidden is refined, shadow rays go to the corners of its bounding box; when they all
  // meet the convex object that hides the representative, nearer than the box, the
  // cluster is provably hidden (Visibility::trace) and stays in the cut as 0, with no
  // error, instead of being refined down to every light (the umbra of an emitter).
  bool visibilityProbes = true;
  // --clear-clusters: a cluster of 16 lights or more whose representative is visible is
  // tested for being visible as a whole without rays (Visibility::boxClear: every surface's
  // bounding volume is apart from the hull of the point and the cluster's box); when it is,
  // the cluster and every cluster under it are known unoccluded: refining them casts no
  // shadow rays, and their error is their unshadowed bounds' alone.
  bool clearClusters = true;
  // --second-samples: before the cut stops, a cluster whose representative is visible and
  // whose estimate holds over kSecondSampleShare of the error limit sends a ray to a second
  // light (its other child's representative); if that one is hidden, the cluster counts as
  // on a shadow boundary and the cut goes on (evaluator.cpp says why).
  bool secondSamples = true;
  // --method stochastic: clusters in the cut, each giving one light drawn at random
  // (stochastic.cpp); its seed (render --seed).
  int stochasticCut = 64;
  uint64_t seed = 1;
};

struct EvalResult {
  Color radiance;
  uint32_t cutSize = 0;
};

class LightEvaluator {
 public:
  virtual ~LightEvaluator() = default;
  virtual EvalResult evaluate(const ShadingPoint& sp, Visibility& vis, EvalStats& stats) const = 0;
  virtual Method method() const = 0;

  // Reconstruction cuts (reconstruction.h); only lightcuts supports them, the others
  // evaluate every point in full.
  virtual bool supportsReconstruction() const { return false; }
  // evaluate(), also recording the cut as a sample for reconstruction.
  virtual EvalResult evaluateRecorded(const ShadingPoint& sp, Visibility& vis, EvalStats& stats,
                                      CutRecord& record) const {
    record.clear();
    return evaluate(sp, vis, stats);
  }
  // The cut that points near 1..4 samples rebuild from their recorded cuts.
  virtual void mergeSamples(const CutRecord* const* samples, int count, MergedCut& out) const {
    (void)samples;
    (void)count;
    out.clear();
  }
  // The direct light at sp over a merged cut.
  virtual EvalResult reconstruct(const ShadingPoint& sp, Visibility& vis, EvalStats& stats,
                                 const MergedCut& merged) const {
    (void)merged;
    return evaluate(sp, vis, stats);
  }
};

// Whether clear tests (CutOptions::clearClusters) pay where `passed` of `tests` passed: a
// test costs about a shadow ray, and a pass spares the rays of a cluster of at least
// kClearMinLights (16) lights, so they pay from one pass in 16. Too few tests to tell:
// yes. Measured (docs/BENCHMARKS.md): 17-24% pass in open scenes, 0.2% in the suite's
// occluded interiors, where they cost 2-10% of a render for nothing.
bool clearTestsPay(uint64_t tests, uint64_t passed);

// `lights` (and `forest`) must outlive the evaluator.
std::unique_ptr<LightEvaluator> makeBruteForce(const LightSet& lights);
std::unique_ptr<LightEvaluator> makeLightcuts(const LightSet& lights, const LightForest& forest,
                                              const CutOptions& options);
std::unique_ptr<LightEvaluator> makeCourseCuts(const LightSet& lights, const LightForest& forest,
                                             const CutOptions& options);
std::unique_ptr<LightEvaluator> makeStochasticLightcuts(const LightSet& lights, const LightForest& forest,
                                                        const CutOptions& options);

namespace detail {
// The visibility coin's rate for each size class of cluster (the log2 of its light count,
// kCoinSizeClasses of them), from the refinements a cut tested at its point, by class: how
// many (`tested`) and how many split into a visible and a hidden half (`split`). A class
// takes the rate of its own refinements, pooled with the next larger classes, then the
// smaller, until `minRefinements` back it; and at least `floorShare` of the rate over all
// of them; 0 when there are none (evaluator.cpp, kCoinRateFloor).
constexpr int kCoinSizeClasses = 24;
void coinRatesBySize(const uint32_t tested[kCoinSizeClasses], const uint32_t split[kCoinSizeClasses],
                     uint32_t minRefinements, double floorShare, double rates[kCoinSizeClasses]);
}  // namespace detail

}  // namespace lc::lightcuts
