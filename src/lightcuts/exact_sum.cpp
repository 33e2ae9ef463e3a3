#include "lightcuts/exact_sum.h"

#include <vector>

namespace lc::lightcuts {

ExactSum unshadowedSum(const LightSet& lights, const LightTree& tree, NodeRef node, const ShadingPoint& sp) {
  // The cluster's lights, in the order of a walk that takes right children first. A
  // subtree's inner nodes are one run of slots (preorder), read in one pass that gives
  // each leaf its place (a node's leaves start where its first leaf is; its left child's
  // start there too, its right child's leftLights() later); then every light is fetched
  // before any is read: walked one by one, each light was a cache miss after the last.
  static thread_local std::vector<uint32_t> order, first;
  if (isLeafRef(node)) {
    order.assign(1, leafLight(node));
  } else {
    const uint32_t count = tree.nodes[node].lights();
    order.resize(count);
    first.resize(count - 1);
    first[0] = 0;
    for (uint32_t k = 0; k + 1 < count; ++k) {
      const LightNode& n = tree.nodes[node + k];
      const uint32_t f = first[k], left = n.leftLights();
      if (n.leftIsLeaf()) order[count - 1 - f] = n.a & LightNode::kValue;
      else first[k + 1] = f;
      if (n.rightIsLeaf()) order[count - 1 - (f + left)] = n.b;
      else first[k + left] = f + left;
    }
  }
  for (uint32_t i : order) __builtin_prefetch(&lights.lights[i]);
  Vec3d sum;
  ExactSum e;
  for (uint32_t i : order) {
    Color mg;
    Vec3 wi;
    float dist;
    const Light& l = lights.lights[i];
    if (!lightContribution(l, lights.groups[l.group], sp, mg, wi, dist)) continue;
    Color c = mg * leafIntensity(l);
    sum += c;
    if (luminance(c) > e.brightest) {
      e.brightest = luminance(c);
      e.brightestDir = wi;
      e.brightestDist = dist;
    }
  }
  e.sum = sum.toFloat();
  return e;
}

Color withVisibility(const ExactSum& e, Visibility& vis, EvalStats& stats, bool knownVisible) {
  if (knownVisible || !(e.brightest > 0)) return e.sum;
  ++stats.shadowRays;
  Color v = vis(e.brightestDir, e.brightestDist);
  stats.occludedRays += isBlack(v);
  return e.sum * v;
}

}  // namespace lc::lightcuts
