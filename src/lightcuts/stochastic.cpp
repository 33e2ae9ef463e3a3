// Stochastic lightcuts (Yuksel 2019, "Stochastic Lightcuts", HPG): a cut of a fixed size
// chosen by the clusters' upper bounds, with no shadow ray while it is formed, then one
// light per cluster drawn by walking down the tree, each step choosing a child with
// probability proportional to its bound. The estimate of a cluster, the drawn light's
// contribution over its probability, is unbiased: a child with a zero bound receives
// nothing, and every other child may be drawn. Hidden and partly hidden clusters cost one
// shadow ray each, whatever their size (the cost of occluded interiors, docs/LIGHTCUTS.md),
// but the image is noisy: each pixel's error is random, not bounded, and falls as more
// samples per pixel (--spp) average it. For previews and animation-free interiors where
// noise is acceptable; Lightcuts keeps the bounded error.
//
// Random numbers come from the shading point's position and normal (and the options'
// seed), so an image does not depend on the thread count.
#include <algorithm>
#include <cstring>
#include <vector>

#include "core/rng.h"
#include "lightcuts/bounds.h"
#include "lightcuts/evaluator.h"

namespace lc::lightcuts {

namespace {

uint64_t pointSeed(const ShadingPoint& sp, uint64_t seed) {
  uint32_t bits[6];
  std::memcpy(bits, &sp.p, sizeof(float) * 3);
  std::memcpy(bits + 3, &sp.n, sizeof(float) * 3);
  uint64_t h = splitmix64(seed);
  for (uint32_t b : bits) h = splitmix64(h ^ b);
  return h;
}

class StochasticLightcuts final : public LightEvaluator {
 public:
  StochasticLightcuts(const LightSet& lights, const LightForest& forest, const CutOptions& o)
      : lights_(lights), forest_(forest), opt_(o) {}

  Method method() const override { return Method::Stochastic; }

  EvalResult evaluate(const ShadingPoint& sp, Visibility& vis, EvalStats& stats) const override {
    struct Entry {
      float bound;
      uint32_t tree, node;
      bool operator<(const Entry& o) const { return bound < o.bound; }
    };
    static thread_local std::vector<Entry> heap, done;
    heap.clear();
    done.clear();
    const BoundFrames frames(sp);
    auto bound = [&](uint32_t t, NodeRef ni) {
      const LightTree& tree = forest_.trees[t];
      ++stats.boundsEvaluated;
      return luminance(clusterBounds(tree.node(lights_, ni), tree.type, tree.bound, sp, frames, nullptr));
    };
    // The cut: refine the cluster of the largest bound until the cut has the size asked for.
    for (uint32_t t = 0; t < forest_.trees.size(); ++t) {
      if (forest_.trees[t].empty()) continue;
      const NodeRef root = forest_.trees[t].root;
      float b = bound(t, root);
      if (b > 0) heap.push_back({b, t, root});
    }
    std::make_heap(heap.begin(), heap.end());
    const size_t target = size_t(std::max(1, opt_.stochasticCut));
    while (!heap.empty() && heap.size() + done.size() < target) {
      std::pop_heap(heap.begin(), heap.end());
      Entry e = heap.back();
      heap.pop_back();
      if (isLeafRef(e.node)) {
        done.push_back(e);
        continue;
      }
      const LightNode& n = forest_.trees[e.tree].nodes[e.node];
      for (NodeRef c : {n.left(e.node), n.right(e.node)}) {
        float b = bound(e.tree, c);
        if (b > 0) {
          heap.push_back({b, e.tree, c});
          std::push_heap(heap.begin(), heap.end());
        }
      }
    }
    done.insert(done.end(), heap.begin(), heap.end());

    // One light per cluster, drawn down the tree in proportion to the children's bounds.
    Rng rng(pointSeed(sp, opt_.seed), 0x5eed);
    Vec3d total;
    for (const Entry& e : done) {
      const LightTree& tree = forest_.trees[e.tree];
      NodeRef ni = e.node;
      double p = 1;
      while (!isLeafRef(ni)) {
        const NodeRef left = tree.nodes[ni].left(ni), right = tree.nodes[ni].right(ni);
        const float a = bound(e.tree, left), b = bound(e.tree, right);
        if (!(a + b > 0)) {
          p = 0;
          break;
        }
        const double pa = double(a) / (double(a) + double(b));
        const bool goLeft = rng.uniformDouble() < pa;
        p *= goLeft ? pa : 1 - pa;
        ni = goLeft ? left : right;
      }
      if (!(p > 0)) continue;
      const Light& l = lights_.lights[leafLight(ni)];
      Color mg;
      Vec3 wi;
      float dist;
      if (!lightContribution(l, lights_.groups[l.group], sp, mg, wi, dist)) continue;
      ++stats.shadowRays;
      Color v = vis(wi, dist);
      stats.occludedRays += isBlack(v);
      total += Vec3d(mg * v * l.intensity) * (1.0 / p);
    }
    const uint32_t cutSize = uint32_t(done.size());
    stats.recordCut(cutSize);
    return {vmax(total.toFloat(), Color(0)), cutSize};
  }

 private:
  const LightSet& lights_;
  const LightForest& forest_;
  CutOptions opt_;
};

}  // namespace

std::unique_ptr<LightEvaluator> makeStochasticLightcuts(const LightSet& lights, const LightForest& forest,
                                                        const CutOptions& options) {
  return std::make_unique<StochasticLightcuts>(lights, forest, options);
}

}  // namespace lc::lightcuts
