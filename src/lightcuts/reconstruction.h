// Reconstruction cuts (Walter et al. 2005, sec. 5): share the work of lightcuts between
// nearby shading points. A sparse set of "samples" (in the renderer: every Nth pixel in x
// and y) get a full lightcut, recorded as a CutRecord: the cut's nodes with what the shadow
// ray of each node's representative found. A point between samples then takes the light
// tree top down (mergeCuts does it as a merge of the samples' entries, with the walk's
// result) and, at each node, looks at what its samples did there:
//   - some sample refined the node (its cut lies below): descend to the children;
//   - every sample kept the node (or an ancestor) and found it occluded: it contributes 0
//     (unless a probe finds its group visible at the point: MergedCut::hidden);
//   - every sample kept it and found it visible (or had nothing to test): the node's
//     estimate at this point, without a shadow ray;
//   - the samples disagree, or the path went through glass: the estimate with one shadow
//     ray, as lightcuts would.
// Where the samples' cuts differ, the point takes the finer one, except where every
// sample saw the node (or all of its part of the cut below it) visible with first-order
// estimates (estimate.h), smooth and unoccluded: there the coarser cut's second-order
// error is small at the point too, and the coarser is kept. The point's material and
// geometric terms are its own (textures, normals, highlights stay sharp); only visibility
// and the choice of clusters are borrowed, where all its samples agree. Shadow rays drop
// from the cut size to those of nodes near shadow boundaries. The caller decides which
// samples are similar enough to use (the renderer: the same surface, normals within ~25
// degrees); a feature thinner than the sample spacing that all samples miss is the
// method's blind spot.
#pragma once

#include <cstdint>
#include <vector>

#include "lightcuts/eval_stats.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/merged_batch.h"
#include "lightcuts/shading.h"
#include "core/light.h"

namespace lc::lightcuts {


// What a sample's shadow ray toward a cut node's representative found.
enum class CutVisibility : uint8_t {
  Visible = 0,   // unoccluded (visibility exactly 1)
  Occluded = 1,  // blocked
  Untested = 2,  // no ray: the representative contributes nothing at the sample
  Partial = 3,   // through glass: a colour between 0 and 1
};

// A sample's cut: per tree, its nodes in preorder (LightTree::preorderNodes) with their
// CutVisibility and whether the node's first-order estimate was used (estimate.h), packed
// as preorder << 3 | firstOrder << 2 | visibility.
struct CutRecord {
  std::vector<uint32_t> entries;
  // Per entry: its node, so that a merge goes from entry to entry without walking the
  // tree above them.
  std::vector<NodeRef> nodes;
  // Per entry: the first-order estimate over the representative's (both unshadowed), 1
  // where the first-order estimate was not used. A point near the sample borrows it: the
  // correction changes with the point far more slowly than the contribution does.
  std::vector<float> factor;
  // Per entry: 1 where the node is a small cluster of spots that the sample estimated by its
  // exact unshadowed sum (across the surface's horizon or a cone's edge, exact_sum.h): a
  // spot's cone ends in a step, so its representative is a 0-or-all sample of the cluster
  // there, and a point near the sample sums it too (all but the dimmest, whose error adds up
  // to at most an eighth of the cut's: kUnsummedShare, evaluator.cpp). Empty or shorter:
  // none. (Omni and oriented clusters fade to 0 at the horizon; summing them at points as
  // well cost the Roman hall ~20% of its render for 0.1% of p99 error: docs/LIGHTCUTS.md.)
  std::vector<uint8_t> summed;
  std::vector<uint32_t> treeBegin;  // entries of tree t: [treeBegin[t], treeBegin[t + 1])
  // entries.size() + 1 values: rough[k] = how many entries before entry k are not visible
  // with a first-order estimate, so that a merge checks any run of entries at once. Filled
  // by finish(); a record without it has it computed by each merge that uses it.
  std::vector<uint32_t> rough;
  Vec3 point;                       // the sample's shading point
  bool valid = false;               // false: no cut was recorded (the caller's miss)

  void clear() {
    entries.clear();
    nodes.clear();
    factor.clear();
    summed.clear();
    treeBegin.clear();
    rough.clear();
    valid = false;
  }
  // Fills `rough` from `entries` (a sample is merged several times: ~7 on average in the
  // church at 512x512, where counting them at every merge was 13% of the merge's time).
  void finish() { countRough(entries, rough); }
  static void countRough(const std::vector<uint32_t>& e, std::vector<uint32_t>& rough) {
    rough.resize(e.size() + 1);
    uint32_t n = 0;
    rough[0] = 0;
    for (size_t k = 0; k < e.size(); ++k) {
      n += !(visibilityOf(e[k]) == CutVisibility::Visible && firstOrderOf(e[k]));
      rough[k + 1] = n;
    }
  }
  static uint32_t pack(uint32_t preorder, CutVisibility v, bool firstOrder = false) {
    return preorder << 3 | uint32_t(firstOrder) << 2 | uint32_t(v);
  }
  static uint32_t preorderOf(uint32_t entry) { return entry >> 3; }
  static CutVisibility visibilityOf(uint32_t entry) { return CutVisibility(entry & 3); }
  static bool firstOrderOf(uint32_t entry) { return (entry >> 2 & 1) != 0; }
};

// The cut a point rebuilds from a set of samples; it depends on the samples only, so every
// point that uses the same samples (a cell of pixels) shares one.
struct MergedCut {
  struct Node {
    Color intensity;  // the node's summed intensity
    uint32_t rep;     // its representative light (whose group it lights with)
    bool needsRay;    // the samples disagree, went through glass, or tested nothing
    bool batched;     // also in `batch` (no ray, an omni or oriented light)
    // The samples disagree about its visibility (some found it occluded, some not), or saw
    // it through glass: a shadow boundary may cross the samples' span.
    bool disagree;
    // The first-order factor (CutRecord::factor) of the samples whose cut holds the node,
    // averaged, when every sample used first-order estimates there; else 1.
    float factor;
    uint32_t tree;  // where it is in the forest
    NodeRef node;
    // A sample that kept the node estimated it by its exact sum (CutRecord::summed): the
    // point does too, times the visibility of its brightest light there, one shadow ray
    // (withVisibility, exact_sum.h), as a spot node's representative always gets one.
    bool summed = false;
  };
  const LightForest* forest = nullptr;  // the merge's (summed nodes walk its trees)
  std::vector<Node> nodes;  // without the nodes every sample found occluded
  std::vector<uint32_t> rayNodes;  // the indices in `nodes` of those not batched, in order
  uint32_t occluded = 0;    // how many those were (they are in the cut, contributing 0)
  MergedBatch batch;        // the batched nodes again, four lanes at a time
  // The batched nodes in groups of kGroupSize, in batch order (neighbours in the tree:
  // lights near each other). Each group has a probe, its brightest node: a point sends it
  // a shadow ray when the group holds over a share of its light (groupProbeShare), and if
  // it is hidden there, where every sample saw it, the point tests each node of the group
  // (a shadow thinner than the sample spacing: the blind spot of borrowed visibility).
  static constexpr uint32_t kGroupSize = 32;  // eight blocks
  std::vector<uint32_t> batchNodes;  // per batched node: its index in `nodes`
  std::vector<uint32_t> groupProbe;  // per group: the index in `nodes` of its probe
  // The nodes every sample found occluded (omni and oriented lights; the others are only
  // counted in `occluded`), in groups of kGroupSize in the walk's order, each with its
  // brightest node as probe: a group whose light at a point (its probe's times hiddenScale)
  // would be over the probe share sends the probe a ray, and if it is visible there, where
  // no sample saw it, each node of the group gets its own (a gap between occluders thinner
  // than the sample spacing).
  std::vector<Node> hidden;
  std::vector<uint32_t> hiddenProbe;  // per group: the index in `hidden` of its probe
  std::vector<float> hiddenScale;     // per group: its intensity over its probe's (luminance)
  void clear() {
    nodes.clear();
    rayNodes.clear();
    occluded = 0;
    batch.clear();
    batchNodes.clear();
    groupProbe.clear();
    hidden.clear();
    hiddenScale.clear();
    hiddenProbe.clear();
  }
};

// Walks the trees over the cuts of `count` (1..4) samples, as described above.
void mergeCuts(const LightSet& lights, const LightForest& forest, const CutRecord* const* samples, int count,
               MergedCut& out);

// The share of the merged cut's unshadowed diffuse light at (p, n) (a sample's point and
// normal) that comes from nodes its samples disagree about (Node::disagree): how much of
// the light a shadow boundary between the samples may touch. 0 when there is no light.
float disagreementShare(const LightSet& lights, const MergedCut& cut, const Vec3& p, const Vec3& n);

struct ReconstructionResult {
  Color radiance;
  uint32_t cutSize = 0;  // nodes in the reconstructed cut
};

// The share of a point's light above which a group of borrowed-visible nodes gets its
// probe ray: half the cut's error ratio. A group that every sample saw and the point does
// not is off by all of its light, so a group left unprobed can cost at most half the error
// the cut is allowed. (A fixed 4% let single groups put the church's and the Roman hall's
// edge pixels 10-20% over at 512x512; docs/LIGHTCUTS.md, "Group probes".)
inline float groupProbeShare(float errorRatio) { return 0.5f * errorRatio; }

// The share of a point's light above which a failed group probe refutes its samples
// (EvalStats::refutingGroupProbes): the cut's error ratio. Such a group alone puts the
// point over --error; the point re-traces it, but its neighbours, whose probes went to
// other lights of the group or who had none, borrow the same wrong visibility, so the
// image's reconstruction refines where one is found (RenderOptions::reconstructRefine).
inline float refutingProbeShare(float errorRatio) { return errorRatio; }

// Direct light at `sp` over a merged cut. Shadow rays go through `vis`; shadow rays and
// the cut are counted in `stats`. A group of borrowed-visible nodes that holds more than
// `probeShare` of the point's light gets a probe ray (groupProbeShare); a failed probe
// whose group holds more than `refuteShare` counts in stats.refutingGroupProbes
// (refutingProbeShare).
ReconstructionResult evaluateMergedCut(const LightSet& lights, const MergedCut& cut, const ShadingPoint& sp,
                                       Visibility& vis, EvalStats& stats, float probeShare, float refuteShare);

}  // namespace lc::lightcuts
