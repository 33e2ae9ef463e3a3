// What the light evaluators count per shading point (per thread, then merged): cut sizes,
// shadow rays, probes, reconstruction. Its own header so that the evaluators
// (evaluator.h) and the reconstruction cuts (reconstruction.h) share it without including
// each other.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace lc::lightcuts {

// Counters summed over shading points (per thread, then merged).
struct EvalStats {
  static constexpr int kHistogramBuckets = 24;  // cut sizes in [2^(i-1), 2^i), bucket 0 = 0
  uint64_t shadingPoints = 0;
  uint64_t cutNodes = 0;         // nodes (lights or clusters) in the cuts
  uint64_t shadowRays = 0;
  uint64_t boundsEvaluated = 0;
  uint64_t reconstructedPoints = 0;  // shading points given a reconstruction cut
  uint64_t reconstructedRays = 0;    // the shadow rays those points sent (in shadowRays too)
  uint64_t probedClusters = 0;       // clusters tested for being hidden as a whole
  uint64_t probesRuledOut = 0;       // of those, failed before any ray (a corner misses the blocker's box)
  uint64_t probeRays = 0;            // the shadow rays those tests cast (in shadowRays too)
  // Bright clusters whose visible representative was checked by a second light's ray before
  // the cut stopped (kSecondSampleShare, evaluator.h; one ray each, in shadowRays too), and
  // those of them found partly hidden.
  uint64_t secondSamples = 0;
  uint64_t secondSamplesHidden = 0;
  uint64_t occludedRays = 0;         // shadow rays that found their light hidden
  uint64_t hiddenClusters = 0;       // clusters kept in a cut as hidden by their probes
  uint64_t clearTests = 0;           // clusters tested for being visible as a whole (boxClear)
  uint64_t clearedClusters = 0;      // those found so
  uint64_t cutsAtMaxCut = 0;         // cuts stopped by --max-cut before their error bound held
  uint64_t groupProbes = 0;          // rays testing groups of borrowed nodes (reconstruction.h)
  // Those that found the samples wrong: a group hidden where every sample saw it, or
  // visible where every sample found it occluded (MergedCut::hidden).
  uint64_t failedGroupProbes = 0;
  // Of those, the ones whose group alone could put the point over the cut's error ratio
  // (refutingProbeShare): a shadow edge the samples stepped over. Reconstruction refines
  // there (RenderOptions::reconstructRefine).
  uint64_t refutingGroupProbes = 0;
  // Time, filled by the caller's Visibility and shading loop where they measure it:
  uint64_t tracedRays = 0;           // rays through the Visibility (shadow and probe rays)
  uint64_t timedRays = 0;            // a random sample of them, timed
  uint64_t timedRayNanos = 0;        // their summed time
  uint64_t litPoints = 0;            // shading points whose light was evaluated
  uint64_t timedPoints = 0;          // a random sample of them, timed
  uint64_t lightingNanos = 0;        // their thread CPU time in light evaluation, rays included
  // The time in light evaluation, estimated from its sample.
  double lightingSeconds() const {
    return timedPoints ? double(lightingNanos) * 1e-9 * double(litPoints) / double(timedPoints) : 0.0;
  }
  // The time in shadow rays, estimated from the sample.
  double shadowRaySeconds() const {
    return timedRays ? double(timedRayNanos) * 1e-9 * double(tracedRays) / double(timedRays) : 0.0;
  }
  std::array<uint64_t, kHistogramBuckets> cutHistogram{};

  void recordCut(uint32_t size) {
    ++shadingPoints;
    cutNodes += size;
    int b = 0;
    while (b + 1 < kHistogramBuckets && (uint64_t(1) << b) <= size) ++b;
    ++cutHistogram[size_t(b)];
  }
  // The counts of points and their cuts, apart from the work. Points whose results are
  // thrown away (where a reconstruction refines: RenderOptions::reconstructRefine) are
  // taken back out of them, their work (rays, bounds) staying counted, so per-point
  // figures divide all the work by the points of the image.
  struct PointCounts {
    uint64_t shadingPoints, reconstructedPoints, cutNodes;
    std::array<uint64_t, kHistogramBuckets> cutHistogram;
  };
  PointCounts pointCounts() const { return {shadingPoints, reconstructedPoints, cutNodes, cutHistogram}; }
  void restorePointCounts(const PointCounts& c) {
    shadingPoints = c.shadingPoints;
    reconstructedPoints = c.reconstructedPoints;
    cutNodes = c.cutNodes;
    cutHistogram = c.cutHistogram;
  }
  void add(const EvalStats& o) {
    shadingPoints += o.shadingPoints;
    cutNodes += o.cutNodes;
    shadowRays += o.shadowRays;
    boundsEvaluated += o.boundsEvaluated;
    reconstructedPoints += o.reconstructedPoints;
    reconstructedRays += o.reconstructedRays;
    probedClusters += o.probedClusters;
    probesRuledOut += o.probesRuledOut;
    probeRays += o.probeRays;
    secondSamples += o.secondSamples;
    secondSamplesHidden += o.secondSamplesHidden;
    occludedRays += o.occludedRays;
    hiddenClusters += o.hiddenClusters;
    clearTests += o.clearTests;
    clearedClusters += o.clearedClusters;
    cutsAtMaxCut += o.cutsAtMaxCut;
    groupProbes += o.groupProbes;
    failedGroupProbes += o.failedGroupProbes;
    refutingGroupProbes += o.refutingGroupProbes;
    tracedRays += o.tracedRays;
    timedRays += o.timedRays;
    timedRayNanos += o.timedRayNanos;
    litPoints += o.litPoints;
    timedPoints += o.timedPoints;
    lightingNanos += o.lightingNanos;
    for (size_t i = 0; i < cutHistogram.size(); ++i) cutHistogram[i] += o.cutHistogram[i];
  }
};

}  // namespace lc::lightcuts
