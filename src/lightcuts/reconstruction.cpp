#include "lightcuts/reconstruction.h"

#include <algorithm>

#include "lightcuts/evaluator.h"

namespace lc::lightcuts {

namespace {

constexpr int kMaxSamples = 4;
constexpr uint8_t kAbove = 0xff;  // the sample refined this node: its cut lies below

struct Item {
  uint32_t node;
  uint8_t state[kMaxSamples];  // per sample: kAbove or the CutVisibility it inherits
};

}  // namespace

void mergeCuts(const LightForest& forest, const CutRecord* const* samples, int count, MergedCut& out) {
  out.clear();
  count = std::clamp(count, 0, kMaxSamples);
  static thread_local std::vector<Item> stack;
  for (uint32_t t = 0; t < forest.trees.size(); ++t) {
    const LightTree& tree = forest.trees[t];
    if (tree.nodes.empty()) continue;
    // Each sample's entries of this tree are in preorder, and so is the walk: one cursor
    // per sample moves forward only.
    uint32_t cursor[kMaxSamples], end[kMaxSamples];
    for (int i = 0; i < count; ++i) {
      cursor[i] = samples[i]->treeBegin[t];
      end[i] = samples[i]->treeBegin[t + 1];
    }
    stack.clear();
    stack.push_back(Item{0, {kAbove, kAbove, kAbove, kAbove}});
    while (!stack.empty()) {
      Item it = stack.back();
      stack.pop_back();
      const LightNode& n = tree.nodes[it.node];
      const uint32_t pre = tree.preorder[it.node];
      bool above = false;
      for (int i = 0; i < count; ++i) {
        if (it.state[i] != kAbove) continue;
        const uint32_t* e = samples[i]->entries.data();
        uint32_t c = cursor[i];
        while (c < end[i] && (e[c] >> 2) < pre) ++c;  // skips nodes of subtrees not walked
        if (c < end[i] && (e[c] >> 2) == pre) {
          it.state[i] = uint8_t(e[c] & 3);
          ++c;
        } else if (n.isLeaf() || c >= end[i]) {
          it.state[i] = uint8_t(CutVisibility::Untested);  // a record of another forest
        } else {
          above = true;
        }
        cursor[i] = c;
      }
      if (above) {
        Item r = it;
        r.node = n.left + 1;
        stack.push_back(r);
        it.node = n.left;
        stack.push_back(it);  // left on top: the walk stays in preorder
        continue;
      }
      int visible = 0, occluded = 0, partial = 0;
      for (int i = 0; i < count; ++i) {
        auto s = CutVisibility(it.state[i]);
        visible += s == CutVisibility::Visible;
        occluded += s == CutVisibility::Occluded;
        partial += s == CutVisibility::Partial;
      }
      if (count > 0 && occluded == count) {
        ++out.occluded;
        continue;
      }
      bool needsRay = occluded > 0 || partial > 0 || visible == 0;
      out.nodes.push_back(MergedCut::Node{n.intensity, n.rep, tree.group, needsRay});
    }
  }
}

ReconstructionResult evaluateMergedCut(const LightSet& lights, const MergedCut& cut, const ShadingPoint& sp,
                                       Visibility& vis, EvalStats& stats) {
  Color total(0);
  for (const MergedCut::Node& node : cut.nodes) {
    Color mg;
    Vec3 wi;
    float dist;
    if (!lightContribution(lights.lights[node.rep], lights.groups[node.group], sp, mg, wi, dist)) continue;
    if (node.needsRay) {
      ++stats.shadowRays;
      mg *= vis(wi, dist);
    }
    total += mg * node.intensity;
  }
  uint32_t cutSize = uint32_t(cut.nodes.size()) + cut.occluded;
  stats.recordCut(cutSize);
  ++stats.reconstructedPoints;
  return {vmax(total, Color(0)), cutSize};
}

}  // namespace lc::lightcuts
