// Internal to the tree builders: clusters as they are formed, merged and finally laid out
// as a LightTree (inner nodes in preorder, leaves as their lights).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "core/rng.h"
#include "lightcuts/light_tree.h"

namespace lc::lightcuts::detail {

struct Cluster {
  Vec3 lo, hi;
  Vec3 axis;
  float cosHalfAngle = 1;
  float halfAngle = 0;  // acos(cosHalfAngle), cached for the metric
  float weight = 0;     // luminance of the summed intensity, relative to the brightest light:
                        // the metric's I (normalised so that sums cannot overflow)
  // Summed RGB intensity, in double: a tree's merges may form long chains (a bright light
  // absorbing millions of dim ones one by one), and a float sum along a chain loses the dim
  // ones. Stored in the node as float once summed. (`weight` stays a float sum: it steers
  // the metric and the representative's choice, where 1e-7 per merge is immaterial, and it
  // keeps the trees of earlier releases bit for bit.)
  Vec3d intensity;
  uint32_t rep = 0;
  int32_t left = -1, right = -1;
  uint32_t count = 1;  // lights below (fills what would be padding)
};

// The lane width of the agglomerative builder's merge-metric rows: 8 where the CPU has AVX2,
// else 4; the trees are the same bit for bit either way. setMetricLanes(4 or 8) forces one
// for tests (8 falls back to 4 without AVX2; 0 = by CPU again) and returns the width in use.
int metricLanes();
int setMetricLanes(int lanes);

// Position a light occupies in its tree: directional lights cluster by the direction
// toward them.
inline Vec3 clusterPoint(const Light& l) {
  return l.type == LightType::Directional ? -l.direction : l.position;
}

inline Cluster leafCluster(const Light& l, uint32_t index) {
  Cluster c;
  c.lo = c.hi = clusterPoint(l);
  bool hasCone = l.type == LightType::Oriented || l.type == LightType::Spot;
  c.axis = hasCone ? l.direction : Vec3(0, 0, 1);
  c.cosHalfAngle = hasCone ? 1.0f : -1.0f;
  c.halfAngle = hasCone ? 0.0f : kPi;
  c.intensity = Vec3d(l.intensity);
  c.weight = luminance(l.intensity);  // buildAgglomerativeTree normalises it
  c.rep = index;
  return c;
}

// Union of two clusters. The representative is one of the children's, chosen with
// probability proportional to intensity from a hash of (seed, children): deterministic
// whatever the thread count.
inline Cluster mergeClusters(const Cluster& a, const Cluster& b, int32_t ia, int32_t ib,
                             bool withCone, uint64_t seed) {
  Cluster c;
  c.lo = vmin(a.lo, b.lo);
  c.hi = vmax(a.hi, b.hi);
  if (withCone) {
    coneUnion(a.axis, a.cosHalfAngle, b.axis, b.cosHalfAngle, c.axis, c.cosHalfAngle);
    c.halfAngle = std::acos(std::clamp(c.cosHalfAngle, -1.0f, 1.0f));
  } else {
    c.axis = a.axis;
    c.cosHalfAngle = -1;
    c.halfAngle = kPi;
  }
  c.intensity = a.intensity + b.intensity;  // in double: cannot overflow (clamped in the node)
  c.weight = a.weight + b.weight;
  uint64_t h = splitmix64(seed ^ (uint64_t(uint32_t(ia)) << 32 | uint32_t(ib)));
  double u = double(h >> 11) * 0x1p-53;
  c.rep = (c.weight > 0 ? u * c.weight < a.weight : u < 0.5) ? a.rep : b.rep;
  c.left = ia;
  c.right = ib;
  c.count = a.count + b.count;
  return c;
}

// A node's box, cone, intensity and representative from its cluster; children unset.
inline void setNodeFromCluster(LightNode& n, const Cluster& c) {
  n.lo = c.lo;
  n.hi = c.hi;
  n.axis = c.axis;
  n.cosHalfAngle = c.cosHalfAngle;
  // Clamped: lights of huge power (sums beyond FLT_MAX) keep finite node intensities.
  n.intensity = vmin(c.intensity.toFloat(), Color(std::numeric_limits<float>::max()));
  n.rep = c.rep;
}

// Lays the cluster tree under `root` out as a LightTree: its inner nodes in preorder, its
// leaves as their lights. `get(id)` returns cluster id (by value or reference).
template <class Get>
void layoutTree(const Get& get, int32_t root, LightTree& tree) {
  tree.nodes.clear();
  const Cluster top = get(root);
  tree.lightTotal = top.count;
  if (top.left < 0) {
    tree.root = leafRef(top.rep);
    return;
  }
  tree.root = 0;
  tree.nodes.reserve(top.count - 1);
  std::vector<int32_t> stack{root};
  while (!stack.empty()) {
    const Cluster c = get(stack.back());
    stack.pop_back();
    const Cluster l = get(c.left), r = get(c.right);
    LightNode& n = tree.nodes.emplace_back();
    setNodeFromCluster(n, c);
    n.setChildren(l.left < 0, l.left < 0 ? l.rep : l.count, r.left < 0, r.rep, c.count);
    if (r.left >= 0) stack.push_back(c.right);
    if (l.left >= 0) stack.push_back(c.left);  // next: a left child's slot follows its parent's
  }
}

// Luminance-weighted and plain sums of a subtree's positions and axes, in double: what a
// node's moments are made from (computeMoments). A node's sums are its left child's plus
// its right child's, whichever pass computes them, so every pass gives the same moments.
struct MomentSums {
  double w = 0, n = 0;
  Vec3d pos, axis;    // sum of w x, sum of w n
  Vec3d posU, axisU;  // unweighted sums
  void add(const MomentSums& b) {
    w += b.w;
    n += b.n;
    pos += b.pos;
    axis += b.axis;
    posU += b.posU;
    axisU += b.axisU;
  }
};

// Fills the moments of the inner nodes under `top` (their nodes written, tree.moments
// sized) and returns the subtree's sums; `known` may supply some subtrees' sums.
MomentSums subtreeMoments(const LightSet& lights, LightTree& tree, NodeRef top,
                          const std::unordered_map<NodeRef, MomentSums>* known = nullptr);

inline void layoutTree(const std::vector<Cluster>& clusters, int32_t root, LightTree& tree) {
  layoutTree([&](int32_t id) -> const Cluster& { return clusters[size_t(id)]; }, root, tree);
}

}  // namespace lc::lightcuts::detail
