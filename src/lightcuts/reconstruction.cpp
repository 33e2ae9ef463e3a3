#include "lightcuts/reconstruction.h"

#include <algorithm>
#include <bit>

#include "lightcuts/exact_sum.h"


namespace lc::lightcuts {

namespace {

constexpr int kMaxSamples = 4;
constexpr uint8_t kAbove = 0xff;  // the sample refined this node: its cut lies below

// A coarser cut is borrowed only from samples this many times closer to each other than
// to the cluster (squared).
constexpr float kCoarsenRatio2 = 8.0f * 8.0f;

// M * G at sp of a merged-cut node's representative, per unit intensity (lightContribution).
inline bool repContribution(const LightSet& lights, const MergedCut::Node& node, const ShadingPoint& sp, Color& mg,
                            Vec3& wi, float& dist) {
  const Light& l = lights.lights[node.rep];
  return lightContribution(l, lights.groups[l.group], sp, mg, wi, dist);
}

// Cuts `count` nodes, in order, into groups of MergedCut::kGroupSize and appends each
// group's brightest (by the luminance of its intensity, `lum(i)`; the first on a tie) to
// `probe`, and, with `scale`, the group's summed luminance over the probe's.
template <class Lum>
void groupProbes(size_t count, Lum lum, std::vector<uint32_t>& probe, std::vector<float>* scale) {
  for (size_t g = 0; g < count; g += MergedCut::kGroupSize) {
    size_t best = g;
    float sum = 0, bestLum = lum(g);
    for (size_t i = g; i < std::min(count, g + MergedCut::kGroupSize); ++i) {
      const float l = lum(i);
      sum += l;
      if (l > bestLum) {
        best = i;
        bestLum = l;
      }
    }
    probe.push_back(uint32_t(best));
    if (scale) scale->push_back(bestLum > 0 ? sum / bestLum : 0.0f);
  }
}

inline float distance2Box(const LightNode& n, const Vec3& p) {
  Vec3 d = vmax(vmax(n.lo - p, p - n.hi), Vec3(0.0f));
  return dot(d, d);
}

constexpr uint8_t kFirstOrderBit = 4;
constexpr uint8_t kStateMask = 7;  // visibility and kFirstOrderBit

// Per sample i, byte i of a 32-bit word (kept in a register): kAbove while the sample's cut
// lies below the current node, else the CutVisibility its cut node there has, with
// kFirstOrderBit when that node used its first-order estimate (then so may every node below
// it: a part of a cluster over which the contribution is smooth is smooth too).
inline uint8_t stateOf(uint32_t state, int i) { return uint8_t(state >> (8 * i)); }
inline void setState(uint32_t& state, int i, uint8_t v) {
  state = (state & ~(0xffu << (8 * i))) | uint32_t(v) << (8 * i);
}

}  // namespace

// The merge goes from entry to entry. Each sample's entries of a tree partition its lights,
// in preorder, so the merged cut's nodes are entries too: at each place the finest of the
// samples', which the coarser samples' entries there cover. A k-way merge over the entries
// reads the tree only at them (their bounds, sums and sizes), never the nodes above them
// that a walk from the root would pass through (about as many again: the merge's perf
// samples went down 10% at 1M paths). Its result is that of the walk from the root that it
// replaced, node for node.
void mergeCuts(const LightSet& lights, const LightForest& forest, const CutRecord* const* samples, int count,
               MergedCut& out) {
  out.clear();
  out.forest = &forest;
  count = std::clamp(count, 0, kMaxSamples);
  // Per sample: how many of its entries before each one are not visible with a
  // first-order estimate (CutRecord::rough), so that any run of entries can be checked at once.
  static thread_local std::vector<uint32_t> counted[kMaxSamples];
  const uint32_t* rough[kMaxSamples];
  for (int i = 0; i < count; ++i) {
    const CutRecord& r = *samples[i];
    if (r.rough.size() != r.entries.size() + 1) {
      CutRecord::countRough(r.entries, counted[i]);
      rough[i] = counted[i].data();
    } else {
      rough[i] = r.rough.data();
    }
  }
  // A merged node's counts are taken from the packed state's bytes at once (below): the low
  // bit of each sample's byte, and a byte sum (not std::popcount: without -mpopcnt that is a
  // call into libgcc).
  static_assert(uint8_t(CutVisibility::Visible) == 0 && uint8_t(CutVisibility::Occluded) == 1 &&
                uint8_t(CutVisibility::Partial) == 3 && kFirstOrderBit == 4 && kMaxSamples == 4);
  const uint32_t lanes = count >= 4 ? 0x01010101u : 0x01010101u & ((1u << (8 * count)) - 1);
  auto ones = [](uint32_t bytes) { return int((bytes * 0x01010101u) >> 24); };
  // The samples' spread: the largest distance between two of them, squared.
  float spread2 = 0;
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) spread2 = std::max(spread2, length2(samples[i]->point - samples[j]->point));
  constexpr uint32_t kNone = ~0u;
  for (uint32_t t = 0; t < forest.trees.size(); ++t) {
    const LightTree& tree = forest.trees[t];
    if (tree.empty()) continue;
    // Per sample: the next entry not yet taken, and the end of its tree's entries.
    uint32_t cursor[kMaxSamples], end[kMaxSamples];
    // Per sample with a state (not kAbove): the preorder position where the entry that gave
    // it ends (the first past its subtree).
    uint32_t coverEnd[kMaxSamples];
    // Per sample: its entries and their nodes (held here: read through the records at every
    // step, the pointers were loaded again after each store to the output).
    const uint32_t* entries[kMaxSamples];
    const NodeRef* entryNodes[kMaxSamples];
    // ... and their factors and summed flags, as many as each record has (a record without
    // them: 1 and not summed).
    const float* factors[kMaxSamples];
    const uint8_t* summedFlags[kMaxSamples];
    size_t factorCount[kMaxSamples], summedCount[kMaxSamples];
    for (int i = 0; i < count; ++i) {
      entries[i] = samples[i]->entries.data();
      entryNodes[i] = samples[i]->nodes.data();
      factors[i] = samples[i]->factor.data();
      factorCount[i] = samples[i]->factor.size();
      summedFlags[i] = samples[i]->summed.data();
      summedCount[i] = samples[i]->summed.size();
      cursor[i] = samples[i]->treeBegin[t];
      end[i] = samples[i]->treeBegin[t + 1];
      coverEnd[i] = 0;
    }
    uint32_t state = 0xffffffffu;  // kAbove for every sample
    const uint32_t treeEnd = 2 * tree.lightCount(tree.root) - 1;  // the preorder positions
    constexpr uint32_t kAhead = 4;  // entries whose nodes are fetched ahead, per sample
    for (uint32_t pos = 0; pos < treeEnd;) {
      // The node at `pos` is that of the samples whose next entry starts there (`exact`);
      // samples whose next entry starts further on are finer here (`above`).
      NodeRef node = pos == 0 ? tree.root : kNone;
      uint32_t exact = 0, exactAt[kMaxSamples], next = kNone;
      for (int i = 0; i < count; ++i) {
        if (stateOf(state, i) != kAbove) {
          if (coverEnd[i] > pos) continue;
          setState(state, i, kAbove);
        }
        const uint32_t* e = entries[i];
        uint32_t c = cursor[i];
        while (c < end[i] && CutRecord::preorderOf(e[c]) < pos) ++c;  // skips entries under a coarser cut kept
        cursor[i] = c;
        if (c >= end[i]) {
          setState(state, i, uint8_t(CutVisibility::Untested));  // a record of another forest
          coverEnd[i] = kNone;
          continue;
        }
        const uint32_t p = CutRecord::preorderOf(e[c]);
        if (p == pos) {
          // The node a few entries on, fetched by the first sample that holds this one
          // (the samples' cuts are mostly the same nodes).
          if (exact == 0 && c + kAhead < end[i]) {
            const NodeRef ahead = entryNodes[i][c + kAhead];
            __builtin_prefetch(isLeafRef(ahead) ? static_cast<const void*>(&lights.lights[leafLight(ahead)])
                                                : static_cast<const void*>(&tree.nodes[ahead]));
          }
          node = entryNodes[i][c];
          setState(state, i, uint8_t(uint8_t(CutRecord::visibilityOf(e[c])) |
                                     (CutRecord::firstOrderOf(e[c]) ? kFirstOrderBit : 0)));
          exact |= 1u << i;
          exactAt[i] = c;
          cursor[i] = c + 1;
        } else {
          next = std::min(next, p);
        }
      }
      if (node == kNone) {
        // No sample's entry starts here: the samples that are finer go on at their next
        // entry (the nodes between are ones no sample kept); if none is, the records do
        // not cover the tree.
        if (next == kNone) break;
        pos = next;
        continue;
      }
      // Only the node's sum, representative and size are needed (and an inner node's box):
      // a leaf's are read off its light, without building its LightNode.
      const bool leaf = isLeafRef(node);
      const LightNode* inner = leaf ? nullptr : &tree.nodes[node];
      const uint32_t rep = leaf ? leafLight(node) : inner->rep;
      const Color intensity = leaf ? leafIntensity(lights.lights[rep]) : inner->intensity;
      const uint32_t nodeEnd = leaf ? pos + 1 : pos + 2 * inner->lights() - 1;
      bool above = false;
      for (int i = 0; i < count; ++i) {
        if (stateOf(state, i) != kAbove) continue;
        if (leaf) {
          setState(state, i, uint8_t(CutVisibility::Untested));  // a record of another forest
          coverEnd[i] = nodeEnd;
        } else {
          above = true;
        }
      }
      if (above) {
        // Samples disagree on how fine the cut is here. Where every sample's cut under this
        // node is visible with first-order estimates, and one sample kept the node itself
        // so, the coarser cut will do.
        const uint8_t vf = uint8_t(CutVisibility::Visible) | kFirstOrderBit;
        bool kept = false, ok = true;
        uint32_t past[kMaxSamples];  // per refining sample: its first entry after the subtree
        for (int i = 0; i < count && ok; ++i) {
          if (stateOf(state, i) == kAbove) continue;
          kept |= stateOf(state, i) == vf && (exact >> i & 1);
          ok = stateOf(state, i) == vf;
        }
        // ... as long as the samples are close together seen from the cluster: the coarser
        // cut was chosen for the sample that kept it.
        ok = ok && kept && distance2Box(*inner, samples[0]->point) >= kCoarsenRatio2 * spread2;
        for (int i = 0; i < count && ok; ++i) {
          if (stateOf(state, i) != kAbove) continue;
          const uint32_t* e = entries[i];
          past[i] = uint32_t(std::lower_bound(e + cursor[i], e + end[i], nodeEnd,
                                              [](uint32_t en, uint32_t p) { return CutRecord::preorderOf(en) < p; }) - e);
          ok = rough[i][past[i]] == rough[i][cursor[i]];
        }
        if (ok) {
          for (int i = 0; i < count; ++i) {
            if (stateOf(state, i) != kAbove) continue;
            cursor[i] = past[i];
            setState(state, i, vf);
            coverEnd[i] = nodeEnd;
          }
          above = false;
        }
      }
      for (uint32_t m = exact; m; m &= m - 1) coverEnd[std::countr_zero(m)] = nodeEnd;
      if (above) {
        // The finer samples' next entries lie in this node's subtree; the samples that kept
        // the node lend it their states until its end.
        pos = next;
        continue;
      }
      pos = nodeEnd;
      // Every sample has a state here (none is kAbove): the counts from its bytes at once,
      // the visibility's two bits and the first-order bit of each.
      const uint32_t lo = state & lanes, hi = state >> 1 & lanes;
      const int visible = ones(lanes & ~(lo | hi)), occluded = ones(lo & ~hi), partial = ones(lo & hi),
                firstOrder = ones(state >> 2 & lanes);
      int exacts = 0;
      float factorSum = 0;
      bool summed = false;
      for (uint32_t m = exact; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        ++exacts;
        factorSum += exactAt[i] < factorCount[i] ? factors[i][exactAt[i]] : 1.0f;
        summed |= exactAt[i] < summedCount[i] && summedFlags[i][exactAt[i]] != 0;
      }
      if (count > 0 && occluded == count) {
        ++out.occluded;
        if (tree.type == LightType::Omni || tree.type == LightType::Oriented)
          out.hidden.push_back(MergedCut::Node{intensity, rep, true, false, false, 1.0f, t, node});
        continue;
      }
      bool needsRay = occluded > 0 || partial > 0 || visible == 0;
      const bool disagree = occluded > 0 || partial > 0;
      const float factor = firstOrder == count && exacts > 0 ? factorSum / float(exacts) : 1.0f;
      const bool batched = !needsRay && !summed && (tree.type == LightType::Omni || tree.type == LightType::Oriented);
      // The group and the batch wait for the pass below, which fetches the lights ahead.
      // (A summed node's factor is 1: the sample that summed it used no first-order estimate.)
      out.nodes.push_back(MergedCut::Node{intensity, rep, needsRay, batched, disagree, factor, t, node, summed});
    }
  }
  // The representatives' lights are scattered over the light array: a cache miss each when
  // read as the walk meets them, so they are fetched a few nodes ahead here.
  constexpr size_t kAhead = 8;
  const size_t nodeCount = out.nodes.size();
  for (size_t i = 0; i < std::min(kAhead, nodeCount); ++i) __builtin_prefetch(&lights.lights[out.nodes[i].rep]);
  for (size_t i = 0; i < nodeCount; ++i) {
    if (i + kAhead < nodeCount) __builtin_prefetch(&lights.lights[out.nodes[i + kAhead].rep]);
    const MergedCut::Node& node = out.nodes[i];
    const Light& rep = lights.lights[node.rep];
    if (node.batched) {
      out.batch.add(rep, lights.groups[rep.group], node.intensity * node.factor);
      out.batchNodes.push_back(uint32_t(i));
    } else {
      out.rayNodes.push_back(uint32_t(i));
    }
  }
  groupProbes(out.batchNodes.size(), [&](size_t i) { return luminance(out.nodes[out.batchNodes[i]].intensity); },
              out.groupProbe, nullptr);
  for (uint32_t& p : out.groupProbe) p = out.batchNodes[p];  // an index into `nodes`
  groupProbes(out.hidden.size(), [&](size_t i) { return luminance(out.hidden[i].intensity); }, out.hiddenProbe,
              &out.hiddenScale);
}

float disagreementShare(const LightSet& lights, const MergedCut& cut, const Vec3& p, const Vec3& n) {
  ShadingPoint sp;
  sp.p = p;
  sp.n = n;
  sp.r = n;
  sp.kd = Color(1);
  sp.ks = Color(0);
  double all = 0, disagreeing = 0;
  for (const MergedCut::Node& node : cut.nodes) {
    Color mg;
    Vec3 wi;
    float dist;
    if (!repContribution(lights, node, sp, mg, wi, dist)) continue;
    const double c = luminance(mg * node.intensity);
    all += c;
    if (node.disagree) disagreeing += c;
  }
  return all > 0 ? float(disagreeing / all) : 0.0f;
}

namespace {

// A node with one shadow ray: its representative's contribution, times the samples'
// first-order factor where it is unoccluded.
Color withRay(const LightSet& lights, const MergedCut& cut, const MergedCut::Node& node, const ShadingPoint& sp,
              Visibility& vis, EvalStats& stats) {
  if (node.summed && cut.forest)
    return withVisibility(unshadowedSum(lights, cut.forest->trees[node.tree], node.node, sp), vis, stats, false);
  Color mg;
  Vec3 wi;
  float dist;
  if (!repContribution(lights, node, sp, mg, wi, dist)) return Color(0);
  ++stats.shadowRays;
  Color v = vis(wi, dist);
  float f = v.x == 1 && v.y == 1 && v.z == 1 ? node.factor : 1.0f;
  return mg * v * (node.intensity * f);
}

// A group probe's ray toward wi: whether it finds the group otherwise than every sample
// did (hidden where they saw it, `samplesSaw`, or visible where none did).
bool probeContradicts(const Vec3& wi, float dist, bool samplesSaw, Visibility& vis, EvalStats& stats) {
  ++stats.shadowRays;
  ++stats.groupProbes;
  if (isBlack(vis(wi, dist)) != samplesSaw) return false;
  ++stats.failedGroupProbes;
  return true;
}

}  // namespace

ReconstructionResult evaluateMergedCut(const LightSet& lights, const MergedCut& cut, const ShadingPoint& sp,
                                       Visibility& vis, EvalStats& stats, float probeShare, float refuteShare) {
  // The nodes that need a ray, one by one (their representatives' lights fetched a few
  // rays ahead: scattered over the light array, each was a cache miss); then the batched
  // nodes four at a time, group by group.
  Color total(0);
  const uint64_t raysBefore = stats.shadowRays;
  constexpr size_t kAhead = 4;
  const std::vector<uint32_t>& rays = cut.rayNodes;
  for (size_t i = 0; i < std::min(kAhead, rays.size()); ++i) __builtin_prefetch(&lights.lights[cut.nodes[rays[i]].rep]);
  for (size_t i = 0; i < rays.size(); ++i) {
    if (i + kAhead < rays.size()) __builtin_prefetch(&lights.lights[cut.nodes[rays[i + kAhead]].rep]);
    total += withRay(lights, cut, cut.nodes[rays[i]], sp, vis, stats);
  }
  const size_t groups = cut.groupProbe.size();
  static thread_local std::vector<Color> groupSum;
  groupSum.resize(groups);
  constexpr size_t kBlocks = MergedCut::kGroupSize / 4;
  for (size_t g = 0; g < groups; ++g) {
    groupSum[g] = evaluateBatch(cut.batch, sp, g * kBlocks, (g + 1) * kBlocks);
    total += groupSum[g];
  }
  // A group that holds a share of the light worth checking gets its probe's ray; hidden,
  // the group's nodes get one each.
  const float worth = probeShare * luminance(total), refuting = refuteShare * luminance(total);
  for (size_t g = 0; g < groups; ++g) {
    if (!(luminance(groupSum[g]) > worth)) continue;
    Color mg;
    Vec3 wi;
    float dist;
    if (!repContribution(lights, cut.nodes[cut.groupProbe[g]], sp, mg, wi, dist) ||
        !probeContradicts(wi, dist, true, vis, stats))
      continue;
    stats.refutingGroupProbes += luminance(groupSum[g]) > refuting;
    total -= groupSum[g];
    for (size_t i = g * MergedCut::kGroupSize; i < std::min(cut.batchNodes.size(), (g + 1) * MergedCut::kGroupSize); ++i)
      total += withRay(lights, cut, cut.nodes[cut.batchNodes[i]], sp, vis, stats);
  }
  // A hidden group that would hold a share worth checking (of the point's light, or of the
  // cut's error floor where the point is dark) gets its probe's ray; visible, the group's
  // nodes get one each.
  const float worthHidden = probeShare * std::max(luminance(total), sp.errorFloor);
  const float refutingHidden = refuteShare * std::max(luminance(total), sp.errorFloor);
  for (size_t g = 0; g < cut.hiddenProbe.size(); ++g) {
    const MergedCut::Node& probe = cut.hidden[cut.hiddenProbe[g]];
    Color mg;
    Vec3 wi;
    float dist;
    if (!repContribution(lights, probe, sp, mg, wi, dist)) continue;
    const float estimate = luminance(mg * probe.intensity) * cut.hiddenScale[g];
    if (!(estimate > worthHidden) || !probeContradicts(wi, dist, false, vis, stats)) continue;
    stats.refutingGroupProbes += estimate > refutingHidden;
    for (size_t i = g * MergedCut::kGroupSize; i < std::min(cut.hidden.size(), (g + 1) * MergedCut::kGroupSize); ++i)
      total += withRay(lights, cut, cut.hidden[i], sp, vis, stats);
  }
  uint32_t cutSize = uint32_t(cut.nodes.size()) + cut.occluded;
  stats.recordCut(cutSize);
  ++stats.reconstructedPoints;
  stats.reconstructedRays += stats.shadowRays - raysBefore;
  return {vmax(total, Color(0)), cutSize};
}

}  // namespace lc::lightcuts
