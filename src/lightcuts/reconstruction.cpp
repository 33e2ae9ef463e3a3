#include "lightcuts/reconstruction.h"

#include <algorithm>


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
    float sum = 0;
    for (size_t i = g; i < std::min(count, g + MergedCut::kGroupSize); ++i) {
      sum += lum(i);
      if (lum(i) > lum(best)) best = i;
    }
    probe.push_back(uint32_t(best));
    if (scale) scale->push_back(lum(best) > 0 ? sum / lum(best) : 0.0f);
  }
}

inline float distance2Box(const LightNode& n, const Vec3& p) {
  Vec3 d = vmax(vmax(n.lo - p, p - n.hi), Vec3(0.0f));
  return dot(d, d);
}

constexpr uint8_t kFirstOrderBit = 4;
constexpr uint8_t kStateMask = 7;  // visibility and kFirstOrderBit

// A node of the walk with, per sample i, byte i of `state`: kAbove, or the CutVisibility it
// inherits, with kFirstOrderBit when that cut node used its first-order estimate (then so
// may every node below it: a part of a cluster over which the contribution is smooth is
// smooth too). One 32-bit word, not a byte array: the walk keeps it in a register (as
// bytes in memory, each push read back what it had just written byte by byte, a
// store-forwarding stall that was a fifth of the merge, perf on the church).
struct Item {
  NodeRef node;
  uint32_t pre;  // its preorder position
  uint32_t state;
};
inline uint8_t stateOf(uint32_t state, int i) { return uint8_t(state >> (8 * i)); }
inline void setState(uint32_t& state, int i, uint8_t v) {
  state = (state & ~(0xffu << (8 * i))) | uint32_t(v) << (8 * i);
}

}  // namespace

void mergeCuts(const LightSet& lights, const LightForest& forest, const CutRecord* const* samples, int count,
               MergedCut& out) {
  out.clear();
  count = std::clamp(count, 0, kMaxSamples);
  static thread_local std::vector<Item> stack;
  // Per sample: how many of its entries before each one are not visible with a
  // first-order estimate, so that any run of entries can be checked at once.
  static thread_local std::vector<uint32_t> rough[kMaxSamples];
  for (int i = 0; i < count; ++i) {
    const std::vector<uint32_t>& e = samples[i]->entries;
    rough[i].resize(e.size() + 1);
    rough[i][0] = 0;
    for (size_t k = 0; k < e.size(); ++k)
      rough[i][k + 1] = rough[i][k] + !(CutRecord::visibilityOf(e[k]) == CutVisibility::Visible &&
                                         CutRecord::firstOrderOf(e[k]));
  }
  // The samples' spread: the largest distance between two of them, squared.
  float spread2 = 0;
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) spread2 = std::max(spread2, length2(samples[i]->point - samples[j]->point));
  for (uint32_t t = 0; t < forest.trees.size(); ++t) {
    const LightTree& tree = forest.trees[t];
    if (tree.empty()) continue;
    // Each sample's entries of this tree are in preorder, and so is the walk: one cursor
    // per sample moves forward only.
    uint32_t cursor[kMaxSamples], end[kMaxSamples];
    for (int i = 0; i < count; ++i) {
      cursor[i] = samples[i]->treeBegin[t];
      end[i] = samples[i]->treeBegin[t + 1];
    }
    stack.clear();
    Item it{tree.root, 0, 0xffffffffu};  // the root, kAbove for every sample
    bool descending = true;   // `it` is the left child just reached, not yet on the stack
    for (;;) {
      if (!descending) {
        if (stack.empty()) break;
        it = stack.back();
        stack.pop_back();
      }
      descending = false;
      // Bit i: sample i's cut holds this very node (its entry is the one before its cursor).
      uint32_t exact = 0;
      const bool leaf = isLeafRef(it.node);
      const LightNode n = tree.node(lights, it.node);
      const uint32_t pre = it.pre;
      bool above = false;
      for (int i = 0; i < count; ++i) {
        if (stateOf(it.state, i) != kAbove) continue;
        const uint32_t* e = samples[i]->entries.data();
        uint32_t c = cursor[i];
        while (c < end[i] && CutRecord::preorderOf(e[c]) < pre) ++c;  // skips nodes of subtrees not walked
        if (c < end[i] && CutRecord::preorderOf(e[c]) == pre) {
          setState(it.state, i, uint8_t(uint8_t(CutRecord::visibilityOf(e[c])) |
                                        (CutRecord::firstOrderOf(e[c]) ? kFirstOrderBit : 0)));
          exact |= 1u << i;
          ++c;
        } else if (leaf || c >= end[i]) {
          setState(it.state, i, uint8_t(CutVisibility::Untested));  // a record of another forest
        } else {
          above = true;
        }
        cursor[i] = c;
      }
      if (above) {
        // Samples disagree on how fine the cut is here. Where every sample's cut under this
        // node is visible with first-order estimates, and one sample kept the node itself
        // so, the coarser cut will do.
        const uint8_t vf = uint8_t(CutVisibility::Visible) | kFirstOrderBit;
        bool kept = false, ok = true;
        const uint32_t last = pre + 2 * n.lights() - 1;  // (`above`: an inner node)  // the subtree's preorder range
        uint32_t past[kMaxSamples];  // per refining sample: its first entry after the subtree
        for (int i = 0; i < count && ok; ++i) {
          if (stateOf(it.state, i) == kAbove) continue;
          kept |= stateOf(it.state, i) == vf && (exact >> i & 1);
          ok = stateOf(it.state, i) == vf;
        }
        // ... as long as the samples are close together seen from the cluster: the coarser
        // cut was chosen for the sample that kept it.
        ok = ok && kept && distance2Box(n, samples[0]->point) >= kCoarsenRatio2 * spread2;
        for (int i = 0; i < count && ok; ++i) {
          if (stateOf(it.state, i) != kAbove) continue;
          const uint32_t* e = samples[i]->entries.data();
          past[i] = uint32_t(std::lower_bound(e + cursor[i], e + end[i], last,
                                              [](uint32_t en, uint32_t p) { return CutRecord::preorderOf(en) < p; }) - e);
          ok = rough[i][past[i]] == rough[i][cursor[i]];
        }
        if (ok) {
          for (int i = 0; i < count; ++i) {
            if (stateOf(it.state, i) != kAbove) continue;
            cursor[i] = past[i];
            setState(it.state, i, vf);
          }
          above = false;
        }
      }
      if (above) {
        // The children inherit states, not the entries (their `exact` starts at 0).
        // The left child is read next (an inner one is the next slot), the right one when
        // the left subtree is done: both are fetched now (a leaf child: its light), so the
        // right one has arrived by then (unfetched, its line was 15% of the merge at 8.1M
        // lights, perf).
        const NodeRef left = n.left(it.node), right = n.right(it.node);
        for (NodeRef c : {left, right})
          __builtin_prefetch(isLeafRef(c) ? static_cast<const void*>(&lights.lights[leafLight(c)])
                                          : static_cast<const void*>(&tree.nodes[c]));
        stack.push_back(Item{right, n.rightPre(pre), it.state});
        it.node = left;  // the left child next: the walk stays in preorder
        it.pre = LightNode::leftPre(pre);
        descending = true;
        continue;
      }
      int visible = 0, occluded = 0, partial = 0, firstOrder = 0, exacts = 0;
      float factorSum = 0;
      for (int i = 0; i < count; ++i) {
        firstOrder += (stateOf(it.state, i) & kFirstOrderBit) != 0;
        if (exact >> i & 1) {
          const std::vector<float>& f = samples[i]->factor;
          ++exacts;
          factorSum += cursor[i] - 1 < f.size() ? f[cursor[i] - 1] : 1.0f;
        }
        auto s = CutVisibility(stateOf(it.state, i) & 3);
        visible += s == CutVisibility::Visible;
        occluded += s == CutVisibility::Occluded;
        partial += s == CutVisibility::Partial;
      }
      if (count > 0 && occluded == count) {
        ++out.occluded;
        if (tree.type == LightType::Omni || tree.type == LightType::Oriented)
          out.hidden.push_back(MergedCut::Node{n.intensity, n.rep, true, false, false, 1.0f, t, it.node});
        continue;
      }
      bool needsRay = occluded > 0 || partial > 0 || visible == 0;
      const bool disagree = occluded > 0 || partial > 0;
      const float factor = firstOrder == count && exacts > 0 ? factorSum / float(exacts) : 1.0f;
      const bool batched = !needsRay && (tree.type == LightType::Omni || tree.type == LightType::Oriented);
      // The group and the batch wait for the pass below, which fetches the lights ahead.
      out.nodes.push_back(MergedCut::Node{n.intensity, n.rep, needsRay, batched, disagree, factor, t, it.node});
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
Color withRay(const LightSet& lights, const MergedCut::Node& node, const ShadingPoint& sp, Visibility& vis,
              EvalStats& stats) {
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
                                       Visibility& vis, EvalStats& stats, float probeShare) {
  // The nodes that need a ray, one by one (their representatives' lights fetched a few
  // rays ahead: scattered over the light array, each was a cache miss); then the batched
  // nodes four at a time, group by group.
  Color total(0);
  constexpr size_t kAhead = 4;
  const std::vector<uint32_t>& rays = cut.rayNodes;
  for (size_t i = 0; i < std::min(kAhead, rays.size()); ++i) __builtin_prefetch(&lights.lights[cut.nodes[rays[i]].rep]);
  for (size_t i = 0; i < rays.size(); ++i) {
    if (i + kAhead < rays.size()) __builtin_prefetch(&lights.lights[cut.nodes[rays[i + kAhead]].rep]);
    total += withRay(lights, cut.nodes[rays[i]], sp, vis, stats);
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
  const float worth = probeShare * luminance(total);
  for (size_t g = 0; g < groups; ++g) {
    if (!(luminance(groupSum[g]) > worth)) continue;
    Color mg;
    Vec3 wi;
    float dist;
    if (!repContribution(lights, cut.nodes[cut.groupProbe[g]], sp, mg, wi, dist) ||
        !probeContradicts(wi, dist, true, vis, stats))
      continue;
    total -= groupSum[g];
    for (size_t i = g * MergedCut::kGroupSize; i < std::min(cut.batchNodes.size(), (g + 1) * MergedCut::kGroupSize); ++i)
      total += withRay(lights, cut.nodes[cut.batchNodes[i]], sp, vis, stats);
  }
  // A hidden group that would hold a share worth checking (of the point's light, or of the
  // cut's error floor where the point is dark) gets its probe's ray; visible, the group's
  // nodes get one each.
  const float worthHidden = probeShare * std::max(luminance(total), sp.errorFloor);
  for (size_t g = 0; g < cut.hiddenProbe.size(); ++g) {
    const MergedCut::Node& probe = cut.hidden[cut.hiddenProbe[g]];
    Color mg;
    Vec3 wi;
    float dist;
    if (!repContribution(lights, probe, sp, mg, wi, dist) ||
        !(luminance(mg * probe.intensity) * cut.hiddenScale[g] > worthHidden) ||
        !probeContradicts(wi, dist, false, vis, stats))
      continue;
    for (size_t i = g * MergedCut::kGroupSize; i < std::min(cut.hidden.size(), (g + 1) * MergedCut::kGroupSize); ++i)
      total += withRay(lights, cut.hidden[i], sp, vis, stats);
  }
  uint32_t cutSize = uint32_t(cut.nodes.size()) + cut.occluded;
  stats.recordCut(cutSize);
  ++stats.reconstructedPoints;
  return {vmax(total, Color(0)), cutSize};
}

}  // namespace lc::lightcuts
