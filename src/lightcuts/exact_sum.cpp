#include "lightcuts/exact_sum.h"

#include <vector>

namespace lc::lightcuts {

ExactSum unshadowedSum(const LightSet& lights, const LightTree& tree, NodeRef node, const ShadingPoint& sp) {
  static thread_local std::vector<NodeRef> stack;
  stack.assign(1, node);
  Vec3d sum;
  ExactSum e;
  while (!stack.empty()) {
    const NodeRef r = stack.back();
    stack.pop_back();
    if (!isLeafRef(r)) {
      stack.push_back(tree.nodes[r].left(r));
      stack.push_back(tree.nodes[r].right(r));
      continue;
    }
    Color mg;
    Vec3 wi;
    float dist;
    const Light& l = lights.lights[leafLight(r)];
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
