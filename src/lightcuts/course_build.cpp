// The seed's light tree (the course project this product grew from): a recursive k-d
// split instead of clustering. At each node the lights are sorted along x, y and z; among
// split positions that keep both halves within the middle half of the node (even splits
// first), the chosen one maximises
//     balance * (1 + positionGap / meanPositionGap + colourGap / meanColourGap)
// where balance = 1 - |2k/n - 1| and the gaps are between neighbouring lights in that
// order (colour as chromaticity, L1). A uniform grid therefore splits at the median, and a
// visible gap between two groups of lights (in space or in colour) wins over the median.
// The seed's node error (for its traversal) is the intensity-weighted mean distance to
// the weighted centroid, times (1 + weighted mean chromaticity distance to the node's).
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>

#include "lightcuts/cluster.h"

namespace lc::lightcuts {

namespace {

using detail::Cluster;

Color chromaticity(const Color& c) {
  double s = double(c.x) + c.y + c.z;  // in double: the float sum may overflow
  return s > 0 ? Color(float(c.x / s), float(c.y / s), float(c.z / s)) : Color(1.0f / 3);
}

struct CourseBuilder {
  const LightSet& lights;
  std::vector<uint32_t> idx;    // light indices, reordered in place by the splits
  // Fixed slots, so the tree does not depend on thread timing: the leaf at position i is
  // cluster i; the inner node that splits at position k is cluster n + k - 1.
  std::vector<Cluster> clusters;
  std::vector<float> exactError;  // per cluster, exact seed error
  uint64_t seed;

  Vec3 point(uint32_t li) const { return detail::clusterPoint(lights.lights[li]); }

  // Best split of idx[b, e): returns the split position (b < k < e) after sorting the range
  // along the chosen axis.
  size_t chooseSplit(size_t b, size_t e) {
    size_t n = e - b;
    size_t kLo = std::max<size_t>(1, n / 4), kHi = std::min(n - 1, (3 * n) / 4);
    if (kHi < kLo) kHi = kLo;
    float bestScore = -1;
    int bestAxis = 0;
    size_t bestK = n / 2;
    std::vector<uint32_t> sorted(idx.begin() + long(b), idx.begin() + long(e));
    for (int axis = 0; axis < 3; ++axis) {
      std::sort(sorted.begin(), sorted.end(), [&](uint32_t p, uint32_t q) {
        float a = point(p)[axis], c = point(q)[axis];
        return a < c || (a == c && p < q);
      });
      float extent = point(sorted.back())[axis] - point(sorted.front())[axis];
      if (!(extent > 0)) continue;
      float meanGap = extent / float(n - 1);
      double colourSum = 0;  // over up to millions of lights: in double
      for (size_t k = 1; k < n; ++k) {
        Vec3 d = vabs(chromaticity(lights.lights[sorted[k]].intensity) -
                      chromaticity(lights.lights[sorted[k - 1]].intensity));
        colourSum += d.x + d.y + d.z;
      }
      float meanColour = float(colourSum / double(n - 1));
      for (size_t k = kLo; k <= kHi; ++k) {
        float gap = point(sorted[k])[axis] - point(sorted[k - 1])[axis];
        Vec3 cd = vabs(chromaticity(lights.lights[sorted[k]].intensity) -
                       chromaticity(lights.lights[sorted[k - 1]].intensity));
        float colourGap = cd.x + cd.y + cd.z;
        float balance = 1 - std::fabs(2 * float(k) / float(n) - 1);
        float score = balance * (1 + gap / meanGap + (meanColour > 0 ? colourGap / meanColour : 0));
        if (score > bestScore) {
          bestScore = score;
          bestAxis = axis;
          bestK = k;
        }
      }
    }
    std::sort(idx.begin() + long(b), idx.begin() + long(e), [&](uint32_t p, uint32_t q) {
      float a = point(p)[bestAxis], c = point(q)[bestAxis];
      return a < c || (a == c && p < q);
    });
    return b + bestK;
  }

  // The seed's per-node error over idx[b, e), exactly.
  // Sums in double: the root's run over every light.
  float nodeError(size_t b, size_t e) const {
    // In double: luminances of huge lights would overflow float sums.
    double w = 0, cx = 0, cy = 0, cz = 0, sr = 0, sg = 0, sb = 0;
    auto lum = [](const Color& c) { return luminance(Vec3d(c)); };
    for (size_t i = b; i < e; ++i) {
      const Light& l = lights.lights[idx[i]];
      double li = lum(l.intensity);
      Vec3 p = point(idx[i]);
      w += li;
      cx += p.x * li, cy += p.y * li, cz += p.z * li;
      sr += l.intensity.x, sg += l.intensity.y, sb += l.intensity.z;
    }
    if (!(w > 0)) return 0;
    Vec3 centroid(float(cx / w), float(cy / w), float(cz / w));
    double smax = std::max({sr, sg, sb, 1e-300});
    Color cm = chromaticity(Color(float(sr / smax), float(sg / smax), float(sb / smax)));
    double dist = 0, spread = 0;
    for (size_t i = b; i < e; ++i) {
      const Light& l = lights.lights[idx[i]];
      double li = lum(l.intensity);
      dist += li * length(point(idx[i]) - centroid);
      Vec3 d = vabs(chromaticity(l.intensity) - cm);
      spread += li * (d.x + d.y + d.z);
    }
    return float((dist / w) * (1 + spread / w));
  }

  // Builds the subtree over idx[b, e) and returns its cluster index.
  int32_t build(size_t b, size_t e) {
    if (e - b == 1) {
      clusters[b] = detail::leafCluster(lights.lights[idx[b]], idx[b]);
      exactError[b] = 0;
      return int32_t(b);
    }
    size_t k = chooseSplit(b, e);
    float err = nodeError(b, e);
    int32_t l, r;
    if (e - b > 4096) {
      // Large halves are independent: build them on both cores.
      tbb::task_group g;
      g.run([&] { l = build(b, k); });
      r = build(k, e);
      g.wait();
    } else {
      l = build(b, k);
      r = build(k, e);
    }
    bool withCone = lights.lights[idx[b]].type == LightType::Oriented ||
                    lights.lights[idx[b]].type == LightType::Spot;
    size_t id = idx.size() + k - 1;
    clusters[id] = detail::mergeClusters(clusters[size_t(l)], clusters[size_t(r)], l, r, withCone, seed);
    exactError[id] = err;
    return int32_t(id);
  }
};

}  // namespace

LightTree buildCourseTree(const LightSet& lights, const std::vector<uint32_t>& indices, LightType type,
                        uint64_t seed) {
  LightTree tree;
  tree.type = type;
  if (indices.empty()) return tree;
  CourseBuilder sb{lights, indices, {}, {}, seed};
  sb.clusters.resize(2 * indices.size() - 1);
  sb.exactError.resize(2 * indices.size() - 1);
  int32_t root = sb.build(0, indices.size());
  detail::layoutTree(sb.clusters, root, tree);
  computeCourseData(lights, tree);
  // Replace the bottom-up error bounds with the exact errors: the inner clusters in
  // preorder, as the layout numbered their slots.
  std::vector<int32_t> stack{root};
  uint32_t slot = 0;
  while (!stack.empty()) {
    const Cluster& c = sb.clusters[size_t(stack.back())];
    const int32_t ci = stack.back();
    stack.pop_back();
    if (c.left < 0) continue;
    tree.course[slot++].error = sb.exactError[size_t(ci)];
    stack.push_back(c.right);
    stack.push_back(c.left);
  }
  return tree;
}

}  // namespace lc::lightcuts
