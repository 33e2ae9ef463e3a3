// Agglomerative light-tree construction (Walter et al. 2005), made O(N log N) in practice
// with the heap-based nearest-neighbour clustering of Walter et al. 2008 ("Fast
// agglomerative clustering for rendering"):
//   - every cluster finds its best partner under the merge metric with a branch-and-bound
//     search in a k-d tree over cluster centres; the k-d nodes carry conservative
//     aggregates (union of boxes, cone of axes, minimum intensity) that give a lower bound
//     of the metric for anything below them;
//   - a min-heap holds (metric, A, best partner of A); popping a pair whose clusters are
//     both alive merges them, the merged cluster takes A's k-d slot and finds its own
//     best partner; stale pairs (partner already merged) are re-queried lazily;
//   - aggregates only ever grow, so they stay sound; the k-d tree is rebuilt over the
//     live clusters each time their number halves, which keeps the bounds tight.
// Up to kExactLimit lights the whole tree is built that way: the exact greedy clustering.
// Larger sets would spend most of the time in those searches at the bottom of the tree,
// where every decision is local anyway, so there the lights are ordered along a Morton
// curve and clustered bottom-up in small groups first (approximate agglomerative
// clustering, Gu et al. 2013: each group of n keeps f(n) = c n^0.4 clusters, merged
// greedily with the same metric by brute-force nearest neighbours); the few thousand
// clusters left are then clustered exactly as above, so the top of the tree, where the
// cut spends its time, is the greedy one. Every merge takes its id from a block fixed in
// advance, so the tree never depends on thread timing.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <array>
#include <queue>
#include <unordered_map>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "lightcuts/cluster.h"

// ApproximateClustering's vector helpers take and return eight-lane vectors only where they
// are inlined (always_inline) into metricRowAvx2, so no call passes one across the ABI that
// GCC warns about (its warning comes where the templates are instantiated, the file's end).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace lc::lightcuts {

namespace {

using detail::Cluster;

// The clusters of one build by id: leaves (0..n-1) made from their lights when asked, so
// that only the n - 1 merges (n..2n-2) take memory (88 bytes each). The merges are left
// unwritten when allocated (BigVector): each is written by the worker that makes it, so
// their pages are first touched in parallel, not zeroed by one thread beforehand.
struct ClusterStore {
  const LightSet& lights;
  const std::vector<uint32_t>& indices;
  BigVector<Cluster> merged;  // id n + k at k
  double weightScale = 1;       // leaf weights: luminance over the brightest light's

  size_t leaves() const { return indices.size(); }
  Cluster get(int32_t id) const {
    size_t i = size_t(id);
    if (i >= leaves()) return merged[i - leaves()];
    const Light& l = lights.lights[indices[i]];
    Cluster c = detail::leafCluster(l, indices[i]);
    c.weight = float(luminance(Vec3d(l.intensity)) * weightScale);
    return c;
  }
  Cluster& mergedAt(int32_t id) { return merged[size_t(id) - leaves()]; }
  uint32_t count(int32_t id) const { return size_t(id) < leaves() ? 1u : merged[size_t(id) - leaves()].count; }
  // Leaves are read in Morton order, their lights scattered in memory: prefetching a batch's
  // indices, then their lights, overlaps the cache misses.
  void prefetch(const int32_t* ids, size_t count) const {
    for (size_t k = 0; k < count; ++k)
      if (size_t(ids[k]) < leaves()) __builtin_prefetch(&indices[size_t(ids[k])]);
    for (size_t k = 0; k < count; ++k)
      if (size_t(ids[k]) < leaves()) __builtin_prefetch(&lights.lights[indices[size_t(ids[k])]]);
  }
};

constexpr int kLeafSize = 4;

// A merge's children as TreeWriter reads them: an inner child by its id, a leaf child by its
// light as ~light (negative). The layout then never looks a leaf's light up in the group's
// index list, which it reads in tree order, at random: at 8.1M lights that lookup was a
// cache miss per leaf, a third of the layout's samples (perf). Set where the builders merge,
// after mergeClusters has hashed the ids for the representative's choice.
inline void nameLeafChildren(Cluster& merged, const Cluster& a, const Cluster& b) {
  if (a.count == 1) merged.left = ~int32_t(a.rep);
  if (b.count == 1) merged.right = ~int32_t(b.rep);
}

// A cluster as the k-d leaves hold it: compact and contiguous, so a leaf scan touches one
// or two cache lines instead of chasing ids into the cluster array.
struct Slot {
  Vec3 lo, hi;
  Vec3 axis;
  float weight;
  float halfAngle;
  int32_t id;  // local cluster index, -1 when the slot is empty
};

struct KdNode {
  Vec3 ulo, uhi;           // union of the boxes of the clusters below
  Vec3 coneAxis{0, 0, 1};  // cone containing the axes of the clusters below
  float coneCos = 1, coneAngle = 0;
  float minWeight = 0;     // lower bound of their weights (weights only grow)
  int32_t alive = 0;
  int32_t child = -1;      // inner node: children at child, child + 1
  int32_t slotBegin = 0, slotEnd = 0;  // leaf: range in `slots_`
  int32_t parent = -1;
};

struct Pair {
  float d;
  int32_t a, b;
  bool operator>(const Pair& o) const {
    if (d != o.d) return d > o.d;
    if (a != o.a) return a > o.a;
    return b > o.b;
  }
};

// The merge metric is only a heuristic for which clusters to merge (the cones stored in
// the tree come from the exact coneUnion), so it uses cheap monotone approximations:
// acos after Abramowitz & Stegun 4.4.45 (error < 7e-5 rad) and 1 - cos t = 2 sin^2(t/2)
// with a 7th-order sine.
inline float fastAcos(float x) {
  x = std::clamp(x, -1.0f, 1.0f);
  float ax = std::fabs(x);
  float r = std::sqrt(1 - ax) * (1.5707288f + ax * (-0.2121144f + ax * (0.0742610f - 0.0187293f * ax)));
  return x >= 0 ? r : kPi - r;
}
inline float oneMinusCos(float t) {
  float u = 0.5f * std::clamp(t, 0.0f, kPi), u2 = u * u;
  float s = u * (1 - u2 * (1.0f / 6 - u2 * (1.0f / 120 - u2 * (1.0f / 5040))));
  return 2 * s * s;
}

// Half-angle of the union of two cones, consistent with coneUnion().
inline float unionHalfAngle(float ta, float tb, float td) {
  if (std::min(td + tb, kPi) <= ta) return ta;
  if (std::min(td + ta, kPi) <= tb) return tb;
  return std::min(kPi, 0.5f * (ta + td + tb));
}

// Greedy clustering of a set of clusters down to `target` survivors. Works on a local,
// compact copy of its input (cache-friendly); merged clusters get ids idBase, idBase+1, ...
class AgglomerativeBuilder {
 public:
  AgglomerativeBuilder(bool withCone, float coneWeight, uint64_t seed)
      : withCone_(withCone), c_(coneWeight), c2_(coneWeight * coneWeight), seed_(seed) {}

  // Clusters `ids` (indices into `all`) until `target` remain. Appends the merged clusters,
  // with children as global ids, to `created` and returns the global ids of the survivors.
  std::vector<int32_t> reduce(const ClusterStore& all, const std::vector<int32_t>& ids,
                              size_t target, int32_t idBase, std::vector<Cluster>& created,
                              bool parallelQueries) {
    size_t n = ids.size();
    if (n <= std::max<size_t>(target, 1)) return ids;
    cl_.clear();
    cl_.reserve(2 * n);
    global_.clear();
    global_.reserve(2 * n);
    for (int32_t g : ids) {
      cl_.push_back(all.get(g));
      global_.push_back(g);
    }
    slotOf_.assign(2 * n, -1);
    dead_.assign(2 * n, 0);
    std::vector<int32_t> local(n);
    for (size_t i = 0; i < n; ++i) local[i] = int32_t(i);
    buildKd(local);

    std::vector<Pair> initial(n);
    auto query = [&](size_t i) {
      auto [d, b] = best(int32_t(i));
      initial[i] = Pair{d, int32_t(i), b};
    };
    if (parallelQueries)
      tbb::parallel_for(size_t(0), n, query);
    else
      for (size_t i = 0; i < n; ++i) query(i);
    std::priority_queue<Pair, std::vector<Pair>, std::greater<Pair>> heap(std::greater<Pair>(),
                                                                          std::move(initial));
    size_t alive = n;
    while (alive > target && !heap.empty()) {
      Pair p = heap.top();
      heap.pop();
      if (dead_[size_t(p.a)]) continue;
      if (p.b < 0 || dead_[size_t(p.b)]) {
        auto [d, b] = best(p.a);
        heap.push(Pair{d, p.a, b});
        continue;
      }
      int32_t c = int32_t(cl_.size());
      int32_t ga = global_[size_t(p.a)], gb = global_[size_t(p.b)];
      cl_.push_back(detail::mergeClusters(cl_[size_t(p.a)], cl_[size_t(p.b)], ga, gb, withCone_, seed_));
      nameLeafChildren(cl_.back(), cl_[size_t(p.a)], cl_[size_t(p.b)]);
      global_.push_back(idBase + int32_t(created.size()));
      created.push_back(cl_.back());
      dead_[size_t(p.a)] = dead_[size_t(p.b)] = 1;
      --alive;
      replace(p.a, p.b, c);
      if (alive <= target) break;
      if (alive * 2 < aliveAtBuild_ && alive > 64) {
        std::vector<int32_t> live;
        live.reserve(alive);
        for (const Slot& s : slots_)
          if (s.id >= 0) live.push_back(s.id);
        buildKd(live);
      }
      auto [d, b] = best(c);
      heap.push(Pair{d, c, b});
    }
    std::vector<int32_t> survivors;
    for (size_t i = 0; i < cl_.size(); ++i)
      if (!dead_[i]) survivors.push_back(global_[i]);
    return survivors;
  }

 private:
  static Slot slotOfCluster(const Cluster& c, int32_t id) {
    return Slot{c.lo, c.hi, c.axis, c.weight, c.halfAngle, id};
  }

  // Merge metric of cluster a with slot x; `cutoff` lets it stop before the trigonometry
  // once the positional part alone is already worse.
  __attribute__((always_inline)) float pairMetric(const Slot& a, const Slot& x, float cutoff) const {
    Vec3 e = vmax(a.hi, x.hi) - vmin(a.lo, x.lo);
    float w = a.weight + x.weight;
    float m = w * dot(e, e);
    if (!withCone_ || m > cutoff) return m;
    float oc = oneMinusCos(unionHalfAngle(a.halfAngle, x.halfAngle, fastAcos(dot(a.axis, x.axis))));
    return m + w * c2_ * oc * oc;
  }

  // Lower bound of pairMetric(a, x) for every cluster x below k-d node n: x's box lies in
  // the union box and x's axis in the node's cone, and the merged cone's half-angle is at
  // least a's and at least half the angle between the axes.
  __attribute__((always_inline)) float lowerBound(const Slot& a, const KdNode& n, float cutoff) const {
    // Per axis: a's extent plus the gap to the union box (at most one side is positive).
    Vec3 ext = (a.hi - a.lo) + vmax(n.ulo - a.hi, Vec3(0)) + vmax(a.lo - n.uhi, Vec3(0));
    float m = dot(ext, ext);
    float w = a.weight + n.minWeight;
    m *= w;
    if (!withCone_ || m > cutoff) return m;
    float td = fastAcos(dot(a.axis, n.coneAxis)) - n.coneAngle;
    float oc = oneMinusCos(std::max(a.halfAngle, 0.5f * std::max(0.0f, td)));
    return m + w * c2_ * oc * oc;
  }

  std::pair<float, int32_t> best(int32_t ai) const {
    const Slot a = slotOfCluster(cl_[size_t(ai)], ai);
    float bestD = kInf;
    int32_t bestId = -1;
    auto scanLeaf = [&](const KdNode& n) {
      for (int32_t s = n.slotBegin; s < n.slotEnd; ++s) {
        const Slot& x = slots_[size_t(s)];
        if (x.id < 0 || x.id == ai) continue;
        float d = pairMetric(a, x, bestD);
        if (d < bestD || (d == bestD && x.id < bestId)) {
          bestD = d;
          bestId = x.id;
        }
      }
    };
    // a's own leaf first: a close candidate early makes the bound prune most of the tree.
    int32_t home = slotOf_[size_t(ai)] >= 0 ? leafOfSlot_[size_t(slotOf_[size_t(ai)])] : -1;
    if (home >= 0) scanLeaf(kd_[size_t(home)]);
    struct Item {
      int32_t node;
      float lb;
    };
    Item stack[128];
    int sp = 0;
    stack[sp++] = Item{0, 0.0f};
    while (sp > 0) {
      Item it = stack[--sp];
      if (it.lb > bestD) continue;
      const KdNode& n = kd_[size_t(it.node)];
      if (n.child < 0) {
        if (it.node != home) scanLeaf(n);
        continue;
      }
      const KdNode& l = kd_[size_t(n.child)];
      const KdNode& r = kd_[size_t(n.child + 1)];
      float lbL = l.alive ? lowerBound(a, l, bestD) : kInf;
      float lbR = r.alive ? lowerBound(a, r, bestD) : kInf;
      // Push the farther child first so the nearer one is searched first.
      if (lbL <= lbR) {
        if (lbR <= bestD && sp < 128) stack[sp++] = Item{n.child + 1, lbR};
        if (lbL <= bestD && sp < 128) stack[sp++] = Item{n.child, lbL};
      } else {
        if (lbL <= bestD && sp < 128) stack[sp++] = Item{n.child, lbL};
        if (lbR <= bestD && sp < 128) stack[sp++] = Item{n.child + 1, lbR};
      }
    }
    return {bestD, bestId};
  }

  // A k-d tree over cluster centres; with cones, over (centre, c * axis) in 6-D so that
  // clusters of different orientation separate as well as distant ones.
  void buildKd(const std::vector<int32_t>& ids) {
    kd_.clear();
    slots_.resize(ids.size());
    leafOfSlot_.assign(ids.size(), -1);
    aliveAtBuild_ = ids.size();
    const int dims = withCone_ ? 6 : 3;
    std::vector<std::array<float, 6>> key(ids.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      const Cluster& c = cl_[size_t(ids[i])];
      Vec3 p = (c.lo + c.hi) * 0.5f;
      key[i] = {p.x, p.y, p.z, c_ * c.axis.x, c_ * c.axis.y, c_ * c.axis.z};
    }
    std::vector<int32_t> order(ids.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = int32_t(i);

    struct Task {
      int32_t node, begin, end;
    };
    std::vector<Task> tasks;
    kd_.push_back(KdNode{});
    tasks.push_back(Task{0, 0, int32_t(ids.size())});
    while (!tasks.empty()) {
      Task t = tasks.back();
      tasks.pop_back();
      if (t.end - t.begin <= kLeafSize) {
        kd_[size_t(t.node)].slotBegin = t.begin;
        kd_[size_t(t.node)].slotEnd = t.end;
        continue;
      }
      float lo[6], hi[6];
      for (int k = 0; k < dims; ++k) lo[k] = kInf, hi[k] = -kInf;
      for (int32_t i = t.begin; i < t.end; ++i)
        for (int k = 0; k < dims; ++k) {
          float v = key[size_t(order[size_t(i)])][size_t(k)];
          lo[k] = std::min(lo[k], v);
          hi[k] = std::max(hi[k], v);
        }
      int axis = 0;
      for (int k = 1; k < dims; ++k)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
      int32_t mid = (t.begin + t.end) / 2;
      std::nth_element(order.begin() + t.begin, order.begin() + mid, order.begin() + t.end,
                       [&](int32_t p, int32_t q) {
                         float cp = key[size_t(p)][size_t(axis)], cq = key[size_t(q)][size_t(axis)];
                         return cp < cq || (cp == cq && p < q);
                       });
      int32_t c = int32_t(kd_.size());
      kd_[size_t(t.node)].child = c;
      kd_.push_back(KdNode{});
      kd_.push_back(KdNode{});
      kd_[size_t(c)].parent = kd_[size_t(c + 1)].parent = t.node;
      tasks.push_back(Task{c + 1, mid, t.end});
      tasks.push_back(Task{c, t.begin, mid});
    }
    for (size_t i = 0; i < order.size(); ++i) {
      int32_t id = ids[size_t(order[i])];
      slots_[i] = slotOfCluster(cl_[size_t(id)], id);
      slotOf_[size_t(id)] = int32_t(i);
    }
    // Aggregates bottom-up: children are created after their parent.
    for (size_t k = kd_.size(); k-- > 0;) {
      KdNode& n = kd_[k];
      if (n.child < 0) {
        n.ulo = Vec3(kInf);
        n.uhi = Vec3(-kInf);
        n.minWeight = kInf;
        for (int32_t s = n.slotBegin; s < n.slotEnd; ++s) {
          leafOfSlot_[size_t(s)] = int32_t(k);
          const Slot& c = slots_[size_t(s)];
          n.ulo = vmin(n.ulo, c.lo);
          n.uhi = vmax(n.uhi, c.hi);
          n.minWeight = std::min(n.minWeight, c.weight);
          if (withCone_) {
            if (s == n.slotBegin) {
              n.coneAxis = c.axis;
              n.coneCos = 1;
            } else {
              coneUnion(n.coneAxis, n.coneCos, c.axis, 1.0f, n.coneAxis, n.coneCos);
            }
          }
        }
        n.alive = n.slotEnd - n.slotBegin;
      } else {
        const KdNode& l = kd_[size_t(n.child)];
        const KdNode& r = kd_[size_t(n.child + 1)];
        n.ulo = vmin(l.ulo, r.ulo);
        n.uhi = vmax(l.uhi, r.uhi);
        n.minWeight = std::min(l.minWeight, r.minWeight);
        n.alive = l.alive + r.alive;
        if (withCone_) coneUnion(l.coneAxis, l.coneCos, r.coneAxis, r.coneCos, n.coneAxis, n.coneCos);
      }
      n.coneAngle = std::acos(std::clamp(n.coneCos, -1.0f, 1.0f));
    }
  }

  // Cluster c (= a + b) takes a's slot; b's slot empties.
  void replace(int32_t a, int32_t b, int32_t c) {
    int32_t sa = slotOf_[size_t(a)], sb = slotOf_[size_t(b)];
    const Cluster& cc = cl_[size_t(c)];
    slots_[size_t(sa)] = slotOfCluster(cc, c);
    slotOf_[size_t(c)] = sa;
    slotOf_[size_t(a)] = -1;
    for (int32_t k = leafOfSlot_[size_t(sa)]; k >= 0; k = kd_[size_t(k)].parent) {
      KdNode& n = kd_[size_t(k)];
      bool boxInside = cc.lo.x >= n.ulo.x && cc.lo.y >= n.ulo.y && cc.lo.z >= n.ulo.z &&
                       cc.hi.x <= n.uhi.x && cc.hi.y <= n.uhi.y && cc.hi.z <= n.uhi.z;
      bool axisInside = !withCone_ || dot(cc.axis, n.coneAxis) >= n.coneCos;
      if (boxInside && axisInside) break;  // ancestors contain this node: nothing changes above
      n.ulo = vmin(n.ulo, cc.lo);
      n.uhi = vmax(n.uhi, cc.hi);
      if (!axisInside) {
        coneUnion(n.coneAxis, n.coneCos, cc.axis, 1.0f, n.coneAxis, n.coneCos);
        n.coneAngle = std::acos(std::clamp(n.coneCos, -1.0f, 1.0f));
      }
    }
    slots_[size_t(sb)].id = -1;
    slotOf_[size_t(b)] = -1;
    for (int32_t k = leafOfSlot_[size_t(sb)]; k >= 0; k = kd_[size_t(k)].parent) --kd_[size_t(k)].alive;
  }

  std::vector<Cluster> cl_;        // local clusters: inputs first, then merges
  std::vector<int32_t> global_;    // global id of each local cluster
  bool withCone_;
  float c_, c2_;
  uint64_t seed_;
  std::vector<KdNode> kd_;
  std::vector<Slot> slots_;
  std::vector<int32_t> slotOf_;      // slot of each local cluster, -1 when not in the k-d tree
  std::vector<int32_t> leafOfSlot_;  // k-d leaf holding each slot
  std::vector<uint8_t> dead_;
  size_t aliveAtBuild_ = 0;
};


// The layout of detail::layoutTree, the subtrees below the top levels in parallel. Slots
// follow from the clusters' light counts: a left child's slot is its parent's + 1, a right
// one's its parent's + the left subtree's light count. Leaves are only named (by their
// light) in their parent, so their lights are never read here.
struct LayoutItem {
  int32_t cluster;  // an inner cluster
  uint32_t slot;
};

class TreeWriter {
 public:
  TreeWriter(ClusterStore& clusters, LightTree& tree) : cl_(clusters), tree_(tree) {}

  // `chunkBegin`: the first merge id of each bottom-up chunk, then the first of the exact
  // top's (empty when the whole tree was clustered exactly). The subtrees under the top's
  // merges are laid out chunk after chunk, and each chunk's merges are given back to the
  // system as soon as its subtrees are written: the build's peak is lights + merges +
  // nodes, and at 10M VPL paths the merges are 715 MB of it. Each subtree's moments are
  // summed as soon as it is written, while its nodes and lights are still in cache (a pass
  // of its own over the finished tree took 0.66 s at 8.1M lights).
  void run(int32_t root, const std::vector<int32_t>& chunkBegin = {}) {
    tree_.lightTotal = uint32_t(cl_.leaves());
    if (size_t(root) < cl_.leaves()) {
      tree_.root = leafRef(cl_.indices[size_t(root)]);
      return;
    }
    tree_.root = 0;
    tree_.nodes.resize(cl_.leaves() - 1);    // unwritten: every node is written below
    tree_.moments.resize(cl_.leaves() - 1);  // likewise
    // Chunk by chunk, the nodes of a chunk are scattered over the array: on huge pages the
    // first chunk alone would fault in all of it while no merge is given back yet.
    if (!chunkBegin.empty()) {
      useHugePages(tree_.nodes, false);
      useHugePages(tree_.moments, false);
    }
    // Top levels serially: the exact top's merges or, for a tree clustered exactly, down to
    // subtrees of at most kTask lights. Those subtrees are written in parallel.
    constexpr uint32_t kTask = 1u << 14;
    const bool chunked = !chunkBegin.empty();
    std::vector<LayoutItem> tasks;
    std::vector<LayoutItem> stack{{root, 0}};
    while (!stack.empty()) {
      LayoutItem it = stack.back();
      stack.pop_back();
      if (chunked ? it.cluster < chunkBegin.back() : cl_.count(it.cluster) <= kTask) {
        tasks.push_back(it);
        continue;
      }
      write(it, stack);
    }
    // Chunk by chunk (a chunk's merges have the ids from its chunkBegin to the next one's).
    std::stable_sort(tasks.begin(), tasks.end(), [](const LayoutItem& a, const LayoutItem& b) { return a.cluster < b.cluster; });
    std::vector<detail::MomentSums> sums(tasks.size());
    size_t from = 0;
    for (size_t c = 0; c + 1 < std::max<size_t>(chunkBegin.size(), 2); ++c) {
      size_t to = from;
      while (to < tasks.size() && (!chunked || tasks[to].cluster < chunkBegin[c + 1])) ++to;
      tbb::parallel_for(size_t(from), to, [&](size_t k) {
        // The subtree's inner nodes fill slots [slot, slot + lights - 1): their pages are
        // faulted in at once rather than one trap at a time.
        const size_t inner = cl_.count(tasks[k].cluster) - 1;
        prefault(&tree_.nodes[tasks[k].slot], inner * sizeof(LightNode));
        prefault(&tree_.moments[tasks[k].slot], inner * sizeof(NodeMoments));
        std::vector<LayoutItem> st{tasks[k]};
        while (!st.empty()) {
          LayoutItem it = st.back();
          st.pop_back();
          write(it, st);
        }
        sums[k] = detail::subtreeMoments(cl_.lights, tree_, tasks[k].slot);
      });
      if (chunked) release(chunkBegin[c], chunkBegin[c + 1]);
      from = to;
    }
    // The top levels' moments, from the subtrees' sums.
    std::unordered_map<NodeRef, detail::MomentSums> known;
    for (size_t k = 0; k < tasks.size(); ++k) known.emplace(tasks[k].slot, sums[k]);
    detail::subtreeMoments(cl_.lights, tree_, 0, &known);
    if (chunked) {
      // Cuts read the nodes at random: on 4 KiB pages a gigabyte of them is a TLB miss per
      // read (khugepaged collapses under 2 MB a second by default).
      moveToHugePages(tree_.nodes);
      moveToHugePages(tree_.moments);
    }
  }

 private:
  // Writes one inner node; pushes its inner children (left on top).
  void write(const LayoutItem& it, std::vector<LayoutItem>& stack) {
    const Cluster& c = cl_.merged[size_t(it.cluster) - cl_.leaves()];
    LightNode& n = tree_.nodes[it.slot];
    detail::setNodeFromCluster(n, c);
    // A leaf child is named by its light (nameLeafChildren).
    const bool leftLeaf = c.left < 0, rightLeaf = c.right < 0;
    const uint32_t leftCount = leftLeaf ? 1 : cl_.count(c.left);
    n.setChildren(leftLeaf, leftLeaf ? uint32_t(~c.left) : leftCount, rightLeaf, rightLeaf ? uint32_t(~c.right) : 0,
                  c.count);
    if (!rightLeaf) stack.push_back(LayoutItem{c.right, it.slot + leftCount});
    if (!leftLeaf) stack.push_back(LayoutItem{c.left, it.slot + 1});
    // The moments pass that follows reads the leaves' lights.
    if (leftLeaf) __builtin_prefetch(&cl_.lights.lights[uint32_t(~c.left)]);
    if (rightLeaf) __builtin_prefetch(&cl_.lights.lights[uint32_t(~c.right)]);
  }

  // Gives the pages of merges [a, b) back to the system (nothing reads them again; the
  // pages at either end may hold other merges and stay).
  void release(int32_t a, int32_t b) const {
#if defined(__linux__) && defined(MADV_DONTNEED)
    constexpr uintptr_t kPage = 4096;
    const uintptr_t lo = reinterpret_cast<uintptr_t>(cl_.merged.data() + (size_t(a) - cl_.leaves()));
    const uintptr_t hi = reinterpret_cast<uintptr_t>(cl_.merged.data() + (size_t(b) - cl_.leaves()));
    const uintptr_t first = (lo + kPage - 1) / kPage * kPage, last = hi / kPage * kPage;
    if (first < last) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
#else
    (void)a;
    (void)b;
#endif
  }

  ClusterStore& cl_;
  LightTree& tree_;
};

}  // namespace

namespace {

// The bottom-up stage for large light sets (AAC-HQ parameters of Gu et al. 2013).
class ApproximateClustering {
 public:
  static constexpr size_t kGroup = 20;  // delta: lights per bottom group
  static constexpr double kAlpha = 0.4;

  ApproximateClustering(ClusterStore& all, bool withCone, float coneWeight, uint64_t seed)
      : all_(all), withCone_(withCone), c2_(coneWeight * coneWeight), seed_(seed), lanes_(detail::metricLanes()) {}

  // Clusters kept by a group of n: f(n) = c n^alpha with f(delta) = delta / 2.
  static size_t keep(size_t n) {
    double c = std::pow(double(kGroup), 1 - kAlpha) / 2;
    return std::max<size_t>(1, size_t(std::ceil(c * std::pow(double(n), kAlpha))));
  }
  // How many clusters the recursion over n lights returns (depends on n alone). Memoized:
  // every level of the recursion asks it for its halves, which have at most two sizes.
  static size_t survivors(size_t n) {
    if (n <= kGroup) return std::min(n, keep(n));
    static thread_local std::unordered_map<size_t, size_t> memo;
    auto it = memo.find(n);
    if (it != memo.end()) return it->second;
    size_t h = n / 2;
    size_t r = std::min(survivors(h) + survivors(n - h), keep(n));
    memo.emplace(n, r);
    return r;
  }

  // A group's surviving cluster ids and, when its greedy merging ran, the metric between
  // them (dm[i * size + j] = metric(set[i], set[j])): the parent group starts from it and
  // computes only the pairs across its two halves.
  struct Reduced {
    std::vector<int32_t> set;
    std::vector<float> dm;  // set.size()^2, or empty
  };

  // Clusters the leaves order[b, e) (Morton order); merged clusters take ids from
  // idBase on. Returns the surviving cluster ids.
  std::vector<int32_t> run(const BigVector<int32_t>& order, size_t b, size_t e, int32_t idBase) {
    return reduce(order, b, e, idBase).set;
  }

 private:
  Reduced reduce(const BigVector<int32_t>& order, size_t b, size_t e, int32_t idBase) {
    size_t n = e - b;
    Reduced r;
    if (n <= kGroup) {
      // Look ahead along the Morton order: the indices of the leaves two groups on, the
      // lights of the next group's (whose indices the previous group fetched).
      const size_t end = order.size();
      for (size_t k = std::min(end, e + kGroup); k < std::min(end, e + 2 * kGroup); ++k)
        __builtin_prefetch(&all_.indices[size_t(order[k])]);
      for (size_t k = e; k < std::min(end, e + kGroup); ++k)
        __builtin_prefetch(&all_.lights.lights[all_.indices[size_t(order[k])]]);
      r.set.assign(order.begin() + long(b), order.begin() + long(e));
      combine(r.set, keep(n), idBase, nullptr, nullptr, r.dm);
      return r;
    }
    size_t h = n / 2;
    Reduced left, right;
    int32_t rightBase = idBase + int32_t(h - survivors(h));
    if (n > 4096) {
      tbb::task_group g;
      g.run([&] { left = reduce(order, b, b + h, idBase); });
      right = reduce(order, b + h, e, rightBase);
      g.wait();
    } else {
      left = reduce(order, b, b + h, idBase);
      right = reduce(order, b + h, e, rightBase);
    }
    r.set = left.set;
    r.set.insert(r.set.end(), right.set.begin(), right.set.end());
    idBase = rightBase + int32_t((n - h) - survivors(n - h));
    combine(r.set, keep(n), idBase, &left, &right, r.dm);
    return r;
  }

  // The clusters of a combine() as columns, several lanes at a time (GCC/Clang vector
  // extensions: SSE on x86-64, or AVX2's eight lanes where the CPU has them; plain code
  // elsewhere). metricRow() computes the merge metric
  // (a.weight + x.weight) * (|union box diagonal|^2 + c^2 (1 - cos union half-angle)^2)
  // from one cluster to all of them, with the operations of the scalar form in its order
  // (min/max/clamp as std:: defines them, no FMA contraction): the trees are the same bit
  // for bit as when it was computed pair by pair, at any lane width (perf, 1M VPLs: 12.3% of
  // the run's samples then, 9.7% with four lanes; at 8.1M lights it was still 18% of the
  // VPL and tree phases, and eight lanes take ~2/5 off it). Both orders, a to x and x to a,
  // as the cone union's rounding is not symmetric.
  using V4 = float __attribute__((vector_size(16)));
  using V8 = float __attribute__((vector_size(32)));
  struct Columns {
    std::vector<float> f[11];  // lo xyz, hi xyz, axis xyz, halfAngle, weight
    void resize(size_t m) {
      for (auto& v : f) v.resize((m + 7) & ~size_t(7), 0.0f);  // whole blocks of 8 lanes
    }
    void set(size_t k, const Cluster& c) {
      const float v[11] = {c.lo.x, c.lo.y, c.lo.z, c.hi.x, c.hi.y, c.hi.z, c.axis.x, c.axis.y, c.axis.z, c.halfAngle, c.weight};
      for (int q = 0; q < 11; ++q) f[q][k] = v[q];
    }
    template <class V>
    __attribute__((always_inline)) V at(int q, size_t k) const {
      V r;
      __builtin_memcpy(&r, &f[q][k], sizeof r);
      return r;
    }
  };
  template <class V>
  static constexpr int kLanes = int(sizeof(V) / sizeof(float));
  template <class V>
  __attribute__((always_inline)) static V vmin(V a, V b) { return b < a ? b : a; }  // std::min(a, b)
  template <class V>
  __attribute__((always_inline)) static V vmax(V a, V b) { return a < b ? b : a; }  // std::max(a, b)
  template <class V>
  __attribute__((always_inline)) static V splat(float x) {
    V r;
    for (int l = 0; l < kLanes<V>; ++l) r[l] = x;
    return r;
  }
  template <class V>
  __attribute__((always_inline)) static V fastAcosV(V x) {
    x = vmin(vmax(x, splat<V>(-1.0f)), splat<V>(1.0f));  // std::clamp(x, -1, 1)
    V ax = x < 0 ? -x : x;
    V t = splat<V>(1.0f) - ax, sq;
    for (int l = 0; l < kLanes<V>; ++l) sq[l] = std::sqrt(t[l]);
    V r = sq * (splat<V>(1.5707288f) +
                ax * (splat<V>(-0.2121144f) + ax * (splat<V>(0.0742610f) - splat<V>(0.0187293f) * ax)));
    return x >= 0 ? r : splat<V>(kPi) - r;
  }
  template <class V>
  __attribute__((always_inline)) static V oneMinusCosV(V t) {
    V u = splat<V>(0.5f) * vmin(vmax(t, splat<V>(0.0f)), splat<V>(kPi)), u2 = u * u;
    V s = u * (splat<V>(1.0f) -
               u2 * (splat<V>(1.0f / 6) - u2 * (splat<V>(1.0f / 120) - u2 * splat<V>(1.0f / 5040))));
    return splat<V>(2.0f) * s * s;
  }
  template <class V>
  __attribute__((always_inline)) static V unionHalfAngleV(V ta, V tb, V td) {
    V pi = splat<V>(kPi);
    V r = vmin(pi, splat<V>(0.5f) * (ta + td + tb));
    r = vmin(td + ta, pi) <= tb ? tb : r;
    return vmin(td + tb, pi) <= ta ? ta : r;
  }
  // The metric from a to cluster k for k in [begin, end) into row[k] (a to k) and col[k] (k to a);
  // lanes past end are computed from padding and not written.
  template <class V>
  __attribute__((always_inline)) inline void metricRowLanes(const Cluster& a, const Columns& x, size_t begin,
                                                            size_t end, float* row, float* col) const {
    constexpr size_t N = size_t(kLanes<V>);
    const V alx = splat<V>(a.lo.x), aly = splat<V>(a.lo.y), alz = splat<V>(a.lo.z);
    const V ahx = splat<V>(a.hi.x), ahy = splat<V>(a.hi.y), ahz = splat<V>(a.hi.z);
    const V aax = splat<V>(a.axis.x), aay = splat<V>(a.axis.y), aaz = splat<V>(a.axis.z);
    const V aw = splat<V>(a.weight), ah = splat<V>(a.halfAngle), c2 = splat<V>(c2_);
    for (size_t k = begin & ~(N - 1); k < end; k += N) {
      V ex = vmax(ahx, x.at<V>(3, k)) - vmin(alx, x.at<V>(0, k));
      V ey = vmax(ahy, x.at<V>(4, k)) - vmin(aly, x.at<V>(1, k));
      V ez = vmax(ahz, x.at<V>(5, k)) - vmin(alz, x.at<V>(2, k));
      V m = ex * ex + ey * ey + ez * ez, m2 = m;
      if (withCone_) {
        V td = fastAcosV(aax * x.at<V>(6, k) + aay * x.at<V>(7, k) + aaz * x.at<V>(8, k));
        V xh = x.at<V>(9, k);
        V o1 = oneMinusCosV(unionHalfAngleV(ah, xh, td)), o2 = oneMinusCosV(unionHalfAngleV(xh, ah, td));
        m += c2 * o1 * o1;
        m2 += c2 * o2 * o2;
      }
      const V w = aw + x.at<V>(10, k), ax = w * m, xa = w * m2;
      if (k >= begin && k + N <= end) {  // a whole block: one store each (not a memcpy call)
        __builtin_memcpy(row + k, &ax, sizeof ax);
        __builtin_memcpy(col + k, &xa, sizeof xa);
        continue;
      }
      for (size_t l = std::max(k, begin); l < std::min(k + N, end); ++l) {
        row[l] = ax[l - k];
        col[l] = xa[l - k];
      }
    }
  }
#if defined(__x86_64__) && defined(__GNUC__)
  // AVX2 only, not FMA: a contracted multiply-add would round differently from the scalar form.
  __attribute__((target("avx2"))) void metricRowAvx2(const Cluster& a, const Columns& x, size_t begin, size_t end,
                                                     float* row, float* col) const {
    metricRowLanes<V8>(a, x, begin, end, row, col);
  }
#endif
  void metricRow(const Cluster& a, const Columns& x, size_t begin, size_t end, float* row, float* col) const {
#if defined(__x86_64__) && defined(__GNUC__)
    if (lanes_ == 8) return metricRowAvx2(a, x, begin, end, row, col);
#endif
    metricRowLanes<V4>(a, x, begin, end, row, col);
  }

  // Greedy merging inside a small set, nearest neighbours by brute force over a matrix of
  // the metric between the set's slots (dm[i * stride + j] = metric(set[i], set[j]), both
  // orders, as the metric's rounding is not symmetric): a merge computes the new cluster's
  // row and column once, and a cluster whose neighbour was merged rescans its row.
  // The halves' matrices, when given, fill their blocks; `out` receives the final matrix.
  void combine(std::vector<int32_t>& set, size_t target, int32_t idBase, const Reduced* left,
               const Reduced* right, std::vector<float>& out) {
    size_t m = set.size();
    if (m <= target) return;
    const size_t stride = m;
    static thread_local std::vector<float> dm;
    dm.resize(m * m);
    // The set's clusters, copied: leaves are made from their lights once, not per pair.
    static thread_local std::vector<Cluster> cs;
    cs.resize(m);
    all_.prefetch(set.data(), m);
    for (size_t i = 0; i < m; ++i) cs[i] = all_.get(set[i]);
    auto D = [&](size_t i, size_t j) -> float& { return dm[i * stride + j]; };
    const size_t mL = left ? left->set.size() : 0;
    const bool haveL = left && !left->dm.empty(), haveR = right && !right->dm.empty();
    if (haveL)
      for (size_t i = 0; i < mL; ++i) std::copy_n(&left->dm[i * mL], mL, &D(i, 0));
    if (haveR) {
      const size_t mR = m - mL;
      for (size_t i = 0; i < mR; ++i) std::copy_n(&right->dm[i * mR], mR, &D(mL + i, mL));
    }
    static thread_local Columns cols;
    static thread_local std::vector<float> colOut;
    cols.resize(m);
    colOut.resize(m);
    for (size_t i = 0; i < m; ++i) cols.set(i, cs[i]);
    // Pairs (i, j > i) not known from the halves: j from the right half for i in the left
    // one, unless the left half's matrix is missing; all j > i where a half's is.
    for (size_t i = 0; i < m; ++i) {
      const size_t b = i < mL ? (haveL ? mL : i + 1) : (haveR ? m : i + 1);
      if (b >= m) continue;
      metricRow(cs[i], cols, b, m, &D(i, 0), colOut.data());
      for (size_t j = b; j < m; ++j) D(j, i) = colOut[j];
    }
    std::vector<float> nnD(m, kInf);
    std::vector<int32_t> nn(m, -1);
    // The nearest neighbour in row i, kept in registers (the stores to nnD and nn at every
    // improvement were half of this function's time): the first of equal minima.
    auto refresh = [&](size_t i) {
      float best = kInf;
      int32_t arg = -1;
      const float* row = &dm[i * stride];
      for (size_t j = 0; j < m; ++j) {
        const float d = j == i ? kInf : row[j];
        if (d < best) {
          best = d;
          arg = int32_t(j);
        }
      }
      nnD[i] = best;
      nn[i] = arg;
    };
    for (size_t i = 0; i < m; ++i) refresh(i);
    int32_t next = idBase;
    while (m > target) {
      size_t i = 0;
      for (size_t k = 1; k < m; ++k)
        if (nnD[k] < nnD[i]) i = k;
      size_t j = size_t(nn[i]);
      int32_t id = next++;
      Cluster merged = detail::mergeClusters(cs[i], cs[j], set[i], set[j], withCone_, seed_);
      nameLeafChildren(merged, cs[i], cs[j]);
      cs[i] = merged;
      all_.mergedAt(id) = cs[i];
      // The merged cluster takes i's place; the last one moves into j's (its row and
      // column with it).
      set[i] = id;
      size_t last = m - 1;
      set[j] = set[last];
      cs[j] = cs[last];
      nnD[j] = nnD[last];
      nn[j] = nn[last];
      if (j != last)
        for (size_t k = 0; k < last; ++k) {
          D(j, k) = D(last, k);
          D(k, j) = D(k, last);
        }
      --m;
      set.resize(m);
      for (size_t k = 0; k < m; ++k)
        if (nn[k] == int32_t(last)) nn[k] = int32_t(j);
      if (i == last) i = j;
      cols.set(j, cs[j]);
      cols.set(i, cs[i]);
      // Row and column i anew (the diagonal entry it also writes is never read).
      metricRow(cs[i], cols, 0, m, &D(i, 0), colOut.data());
      for (size_t k = 0; k < m; ++k)
        if (k != i) D(k, i) = colOut[k];
      refresh(i);
      for (size_t k = 0; k < m; ++k) {
        if (k == i) continue;
        if (nn[k] == int32_t(i) || nn[k] == int32_t(j) || nn[k] < 0) {
          refresh(k);
        } else {
          float d = D(k, i);
          if (d < nnD[k]) {
            nnD[k] = d;
            nn[k] = int32_t(i);
          }
        }
      }
    }
    out.resize(m * m);
    for (size_t i = 0; i < m; ++i) std::copy_n(&dm[i * stride], m, &out[i * m]);
  }

  ClusterStore& all_;
  bool withCone_;
  float c2_;
  uint64_t seed_;
  int lanes_;  // metricRow's lane width (detail::metricLanes)
};

}  // namespace

namespace detail {

namespace {
std::atomic<int> forcedMetricLanes{0};
bool hasAvx2() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}
}  // namespace

int metricLanes() {
  const int forced = forcedMetricLanes.load(std::memory_order_relaxed);
  return forced ? forced : hasAvx2() ? 8 : 4;
}

int setMetricLanes(int lanes) {
  forcedMetricLanes.store(lanes == 8 && !hasAvx2() ? 4 : lanes == 4 || lanes == 8 ? lanes : 0,
                          std::memory_order_relaxed);
  return metricLanes();
}

}  // namespace detail

LightTree buildAgglomerativeTree(const LightSet& lights, const std::vector<uint32_t>& indices,
                                 LightType type, float coneWeight, uint64_t seed, size_t exactLimit,
                                 Progress* progress) {
  // Progress counts lights: the bottom-up chunks take most of a large build.
  constexpr double kChunkShare = 0.85;
  LightTree tree;
  tree.type = type;
  if (indices.empty()) return tree;
  size_t n = indices.size();
  bool withCone = (type == LightType::Oriented || type == LightType::Spot) && coneWeight > 0;
  // Ids: leaves 0..n-1, merges n..2n-2, handed out in fixed blocks.
  ClusterStore clusters{lights, indices, BigVector<Cluster>(n - 1)};
  // Weights relative to the brightest light (luminance in double): the metric's sums and
  // products stay finite whatever the power. Lights of 1e38 would otherwise give inf (or
  // NaN from inf * 0) metrics, and the nearest-neighbour search never found a partner.
  // (Serial passes over millions of lights here took ~0.3 s of one thread at 8.1M: the
  // maximum, the bounds and the Morton order are found in parallel, exactly as in order.)
  constexpr size_t kGrain = size_t(1) << 16;
  {
    double maxLum = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, kGrain), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double m) {
          for (size_t i = r.begin(); i < r.end(); ++i)
            m = std::max(m, luminance(Vec3d(lights.lights[indices[i]].intensity)));
          return m;
        },
        [](double a, double b) { return std::max(a, b); });
    clusters.weightScale = maxLum > 0 && std::isfinite(maxLum) ? 1 / maxLum : 1.0;
  }
  if (n == 1) {
    TreeWriter(clusters, tree).run(0);
    return tree;
  }

  std::vector<int32_t> top;
  std::vector<int32_t> chunkBegin;  // bottom-up: each chunk's first merge id, then the top's
  int32_t nextId = int32_t(n);
  if (n <= exactLimit) {
    for (size_t i = 0; i < n; ++i) top.push_back(int32_t(i));
  } else {
    auto point = [&](size_t i) { return detail::clusterPoint(lights.lights[indices[i]]); };
    const Bounds3 b = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, kGrain), Bounds3(),
        [&](const tbb::blocked_range<size_t>& r, Bounds3 acc) {
          for (size_t i = r.begin(); i < r.end(); ++i) acc.extend(point(i));
          return acc;
        },
        [](const Bounds3& x, const Bounds3& y) { return merge(x, y); });
    BigVector<std::pair<uint32_t, int32_t>> keyed(n);  // written in parallel below
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) keyed[i] = {mortonCode(point(i), b), int32_t(i)};
    });
    tbb::parallel_sort(keyed.begin(), keyed.end());
    BigVector<int32_t> order(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) order[i] = keyed[i].second;
    });
    BigVector<std::pair<uint32_t, int32_t>>().swap(keyed);
    // Bottom-up in chunks, each reduced to its survivors; chunks are as large as it takes
    // to leave at most half of exactLimit clusters for the exact top levels.
    size_t chunk = exactLimit;
    while (chunk < n && (n + chunk - 1) / chunk * ApproximateClustering::survivors(chunk) > exactLimit / 2) chunk *= 2;
    size_t chunks = (n + chunk - 1) / chunk;
    std::vector<std::vector<int32_t>> survivors(chunks);
    std::vector<int32_t>& idBase = chunkBegin;
    idBase.resize(chunks);
    for (size_t c = 0; c < chunks; ++c) {
      size_t size = std::min(chunk, n - c * chunk);
      idBase[c] = nextId;
      nextId += int32_t(size - ApproximateClustering::survivors(size));
    }
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
      size_t begin = c * chunk, end = std::min(n, begin + chunk);
      ApproximateClustering aac(clusters, withCone, coneWeight, seed);
      survivors[c] = aac.run(order, begin, end, idBase[c]);
      if (progress) progress->add(kChunkShare * double(end - begin));
    });
    for (const auto& s : survivors) top.insert(top.end(), s.begin(), s.end());
    chunkBegin.push_back(nextId);  // the exact top's merges
  }
  std::vector<Cluster> created;
  AgglomerativeBuilder builder(withCone, coneWeight, seed);
  std::vector<int32_t> root = builder.reduce(clusters, top, 1, nextId, created, true);
  std::copy(created.begin(), created.end(), clusters.merged.begin() + (nextId - int32_t(n)));
  TreeWriter(clusters, tree).run(root[0], chunkBegin);  // nodes and moments
  BigVector<Cluster>().swap(clusters.merged);
  if (progress) progress->add(n <= exactLimit ? double(n) : (1 - kChunkShare) * double(n));
  return tree;
}

}  // namespace lc::lightcuts
