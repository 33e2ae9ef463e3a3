#include "lightcuts/light_tree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <unordered_map>
#include <stdexcept>

#include "core/error.h"

namespace lc::lightcuts {

size_t LightForest::memoryBytes() const {
  size_t b = 0;
  for (const LightTree& t : trees)
    b += t.nodes.size() * sizeof(LightNode) + t.course.size() * sizeof(CourseNodeData) +
         t.moments.size() * sizeof(NodeMoments) +
         t.preorder.size() * sizeof(uint32_t);
  return b;
}

size_t LightForest::nodeCount() const {
  size_t n = 0;
  for (const LightTree& t : trees) n += t.nodes.size();
  return n;
}

void coneUnion(const Vec3& a, float cosA, const Vec3& b, float cosB, Vec3& axis, float& cosOut) {
  if (cosA <= -1 || cosB <= -1) {
    axis = a;
    cosOut = -1;
    return;
  }
  float thetaA = std::acos(std::clamp(cosA, -1.0f, 1.0f));
  float thetaB = std::acos(std::clamp(cosB, -1.0f, 1.0f));
  float thetaD = std::acos(std::clamp(dot(a, b), -1.0f, 1.0f));
  if (std::min(thetaD + thetaB, kPi) <= thetaA) {
    axis = a;
    cosOut = cosA;
    return;
  }
  if (std::min(thetaD + thetaA, kPi) <= thetaB) {
    axis = b;
    cosOut = cosB;
    return;
  }
  float thetaO = (thetaA + thetaD + thetaB) * 0.5f;
  if (thetaO >= kPi) {
    axis = a;
    cosOut = -1;
    return;
  }
  // Rotate a toward b by thetaO - thetaA about a x b (Rodrigues).
  Vec3 k = cross(a, b);
  float kl = length(k);
  if (kl < 1e-12f) {
    axis = a;
    cosOut = -1;
    return;
  }
  k = k / kl;
  float thetaR = thetaO - thetaA;
  float c = std::cos(thetaR), s = std::sin(thetaR);
  axis = normalize(a * c + cross(k, a) * s + k * (dot(k, a) * (1 - c)));
  // Round outward: the cone must contain both inputs despite float error.
  cosOut = std::max(-1.0f, std::cos(thetaO) - 1e-6f);
}

namespace {

// A tree's key: a light group, or (group >= kMixedKey) every group of one kind.
struct GroupKey {
  LightType type;
  uint32_t group;
  bool operator<(const GroupKey& o) const {
    return type != o.type ? type < o.type : group < o.group;
  }
};
constexpr uint32_t kMixedKey = 1u << 16;
uint32_t kindOf(const LightGroup& g) { return uint32_t(g.diffuseOnly) | uint32_t(g.isVpl) << 1; }

// Luminance in double: luminances near FLT_MAX would overflow a float sum.
double lum(const Color& c) { return luminance(Vec3d(c)); }

}  // namespace

namespace {

// Luminance-weighted and plain sums of a subtree's positions and axes, in double.
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

void setMeans(NodeMoments& m, const MomentSums& s) {
  if (s.w > 0) {
    m.centroid = (s.pos / s.w).toFloat();
    m.meanAxis = (s.axis / s.w).toFloat();
  } else {
    m.centroid = (s.posU / s.n).toFloat();
    m.meanAxis = (s.axisU / s.n).toFloat();
  }
}

// Post-order walk with an explicit stack (chains of merges can be deep): fills the moments
// below `top` and returns top's sums. `known(i, sums)` may supply a subtree's sums.
template <class Known>
MomentSums subtreeMoments(const LightSet& lights, LightTree& tree, uint32_t top, const Known& known) {
  BigVector<NodeMoments>& m = tree.moments;
  std::vector<std::pair<uint32_t, bool>> stack{{top, false}};  // node, children done
  std::vector<MomentSums> done;  // the finished subtrees whose parent is not
  while (!stack.empty()) {
    auto [i, expanded] = stack.back();
    stack.pop_back();
    const LightNode& n = tree.nodes[i];
    MomentSums ks;
    if (!expanded && known(i, ks)) {
      done.push_back(ks);
      continue;
    }
    if (n.isLeaf()) {
      // From the leaf's node, not its light: leaves come in tree order and their lights in
      // scene order, a cache miss each (half of this pass at 8.1M lights). The node holds the
      // light's position (directional: the direction toward it, minus its travel direction)
      // and, for oriented and spot lights, its axis. (An omni light's node has no axis: its
      // light is read, to keep the moments momentsOf() defines, though nothing reads an omni
      // tree's mean axis.)
      MomentSums s;
      s.w = lum(n.intensity);
      s.n = 1;
      s.posU = Vec3d(n.lo);
      s.axisU = tree.type == LightType::Directional ? Vec3d(-n.lo)
                : tree.type == LightType::Omni      ? Vec3d(lights.lights[n.rep].direction)
                                                    : Vec3d(n.axis);
      s.pos = s.posU * s.w;
      s.axis = s.axisU * s.w;
      done.push_back(s);
      continue;
    }
    if (!expanded) {
      stack.emplace_back(i, true);
      stack.emplace_back(n.left + 1, false);
      stack.emplace_back(n.left, false);
      continue;
    }
    MomentSums b = done.back();
    done.pop_back();
    done.back().add(b);  // the left child's sums become this node's
    NodeMoments& mi = m[(n.left - 1) / 2];
    setMeans(mi, done.back());
  }
  return done.back();
}

}  // namespace

void computeMoments(const LightSet& lights, LightTree& tree) {
  // The luminance-weighted sums of each subtree's positions and axes, in double, divided
  // once per node: a node's mean is exact to float rounding however many lights it holds
  // and however deep (a mean of the children's float means loses ~1e-7 per level, which a
  // long chain of merges adds up). A subtree of zero weight takes the plain mean. Each
  // node's sums are its left child's plus its right child's, so the subtrees below the
  // top levels are summed in parallel to the same values. Memory: the tree's depth.
  BigVector<NodeMoments>& m = tree.moments;
  m.assign(tree.nodes.size() / 2, NodeMoments{});  // one per inner node
  if (tree.nodes.empty()) return;
  if (tree.preorder.size() != tree.nodes.size()) computePreorder(tree);
  // Top levels: split down to subtrees of at most kTask lights. A node's light count from
  // the preorder: the left subtree spans preorder[right] - preorder[left] = 2 count - 1.
  constexpr uint32_t kTask = 1u << 14;
  std::vector<uint32_t> tasks;
  std::unordered_map<uint32_t, uint32_t> taskOf;  // node -> task
  std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, uint32_t((tree.nodes.size() + 1) / 2)}};
  while (!stack.empty()) {
    auto [i, count] = stack.back();
    stack.pop_back();
    const LightNode& n = tree.nodes[i];
    if (n.isLeaf() || count <= kTask) {
      taskOf.emplace(i, uint32_t(tasks.size()));
      tasks.push_back(i);
      continue;
    }
    uint32_t leftCount = (tree.preorder[n.left + 1] - tree.preorder[n.left] + 1) / 2;
    stack.emplace_back(n.left + 1, count - leftCount);
    stack.emplace_back(n.left, leftCount);
  }
  std::vector<MomentSums> sums(tasks.size());
  auto none = [](uint32_t, MomentSums&) { return false; };
  tbb::parallel_for(size_t(0), tasks.size(),
                    [&](size_t k) { sums[k] = subtreeMoments(lights, tree, tasks[k], none); });
  subtreeMoments(lights, tree, 0, [&](uint32_t i, MomentSums& s) {
    auto t = taskOf.find(i);
    if (t == taskOf.end()) return false;
    s = sums[t->second];
    return true;
  });
}

void computeCourseData(const LightSet& lights, LightTree& tree) {
  if (tree.moments.size() != tree.nodes.size() / 2) computeMoments(lights, tree);
  tree.course = courseNodeData(lights, tree);
}

std::vector<CourseNodeData> courseNodeData(const LightSet& lights, const LightTree& tree) {
  // Bottom-up, from the moments. The mean distance to the centroid is exact for leaves and
  // bounded above through the triangle inequality for inner nodes; the seed builder
  // overwrites it with exact values.
  std::vector<CourseNodeData> sd(tree.nodes.size(), CourseNodeData{});
  std::vector<float> spread(tree.nodes.size(), 0.0f);
  auto chroma = [](const Color& c) {
    double s = double(c.x) + c.y + c.z;  // in double: the float sum may overflow
    return s > 0 ? Color(float(c.x / s), float(c.y / s), float(c.z / s)) : Color(1.0f / 3);
  };
  for (size_t i = tree.nodes.size(); i-- > 0;) {
    const LightNode& n = tree.nodes[i];
    CourseNodeData& d = sd[i];
    const NodeMoments mo = tree.momentsOf(lights, i);
    d.position = mo.centroid;
    if (n.isLeaf()) {
      d.direction = mo.meanAxis;
      d.error = 0;
      continue;
    }
    const CourseNodeData& da = sd[n.left];
    const CourseNodeData& db = sd[n.left + 1];
    d.direction = length2(mo.meanAxis) > 0 ? normalize(mo.meanAxis) : da.direction;
    // Relative weights (in double: luminances near FLT_MAX would overflow their sum).
    double la = lum(tree.nodes[n.left].intensity), lb = lum(tree.nodes[n.left + 1].intensity);
    float wa = 0.5f, wb = 0.5f, w = 1;
    if (la + lb > 0) wa = float(la / (la + lb)), wb = float(lb / (la + lb));
    float meanDist = (wa * (da.error / (1 + spread[n.left]) + length(da.position - d.position)) +
                      wb * (db.error / (1 + spread[n.left + 1]) + length(db.position - d.position))) / w;
    Color cm = chroma(n.intensity);
    Vec3 ca = vabs(chroma(tree.nodes[n.left].intensity) - cm), cb = vabs(chroma(tree.nodes[n.left + 1].intensity) - cm);
    spread[i] = (wa * (spread[n.left] + ca.x + ca.y + ca.z) + wb * (spread[n.left + 1] + cb.x + cb.y + cb.z)) / w;
    d.error = meanDist * (1 + spread[i]);
  }
  return sd;
}

void computePreorder(LightTree& tree) {
  tree.preorder.assign(tree.nodes.size(), 0);
  if (tree.nodes.empty()) return;
  std::vector<uint32_t> stack{0};
  uint32_t next = 0;
  while (!stack.empty()) {
    uint32_t i = stack.back();
    stack.pop_back();
    tree.preorder[i] = next++;
    const LightNode& n = tree.nodes[i];
    if (n.isLeaf()) continue;
    stack.push_back(n.left + 1);
    stack.push_back(n.left);
  }
}

void computeDirectionCones(const LightSet& lights, LightTree& tree) {
  // Bottom-up in double: each inner node's cone is the smallest cone holding its children's
  // (as coneUnion), so a node's cone holds every light below it. A float cosine cannot
  // tell half-angles below ~3.5e-4 apart (cos rounds to 1), so each node stores
  // cos(half-angle + kMargin), rounded down: the angle it stands for is never too small.
  constexpr double kMargin = 1e-3;
  const size_t n = tree.nodes.size();
  std::vector<Vec3d> axis(n);
  std::vector<double> angle(n);
  auto unit = [](const Vec3d& v) {
    double l = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return l > 0 ? v / l : Vec3d(0, 0, 1);
  };
  auto dotd = [](const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  for (size_t i = n; i-- > 0;) {
    LightNode& nd = tree.nodes[i];
    if (nd.isLeaf()) {
      axis[i] = unit(Vec3d(lights.lights[nd.rep].direction));
      angle[i] = 0;
    } else {
      const Vec3d a = axis[nd.left], b = axis[nd.left + 1];
      const double ta = angle[nd.left], tb = angle[nd.left + 1];
      const double ab = std::clamp(dotd(a, b), -1.0, 1.0), td = std::acos(ab);
      if (ta >= kPi || tb >= kPi) {
        axis[i] = a;
        angle[i] = kPi;
      } else if (td + tb <= ta) {
        axis[i] = a;
        angle[i] = ta;
      } else if (td + ta <= tb) {
        axis[i] = b;
        angle[i] = tb;
      } else {
        const double to = (ta + td + tb) * 0.5;
        Vec3d t = b - a * ab;  // toward b, orthogonal to a
        double tl = std::sqrt(dotd(t, t));
        if (to >= kPi || !(tl > 1e-12)) {
          axis[i] = a;
          angle[i] = kPi;
        } else {
          const double phi = to - ta;  // rotate a toward b by this much
          axis[i] = unit(a * std::cos(phi) + t * (std::sin(phi) / tl));
          angle[i] = to;
        }
      }
    }
    const double widened = angle[i] + kMargin;
    nd.axis = axis[i].toFloat();
    nd.cosHalfAngle =
        widened >= kPi ? -1.0f : std::nextafter(float(std::cos(widened)), -1.0f);
  }
}

LightForest buildLightForest(const LightSet& lights, const TreeBuildOptions& options) {
  auto t0 = std::chrono::steady_clock::now();
  std::map<GroupKey, std::vector<uint32_t>> groups;
  for (size_t i = 0; i < lights.lights.size(); ++i) {
    const Light& l = lights.lights[i];
    if (!(luminance(l.intensity) > 0)) continue;
    groups[GroupKey{l.type, l.group}].push_back(uint32_t(i));
  }
  // A kind with more groups than kMaxGroupTrees shares one tree that mixes them (measured:
  // 30,000 point lights, each with its own attenuation, 2.5x faster than a tree each; cutting
  // the groups, sorted, into 16 trees with tighter envelopes was 10% faster there but left
  // more pixels over 2% on 15,000 spots with their own cones).
  std::map<GroupKey, size_t> perKind;
  for (auto& [k, v] : groups) ++perKind[GroupKey{k.type, kindOf(lights.groups[k.group])}];
  for (auto it = groups.begin(); it != groups.end();) {
    if (it->first.group >= kMixedKey) {
      ++it;
      continue;
    }
    const GroupKey kind{it->first.type, kindOf(lights.groups[it->first.group])};
    if (perKind[kind] <= kMaxGroupTrees) {
      ++it;
      continue;
    }
    std::vector<uint32_t>& mixed = groups[GroupKey{kind.type, kMixedKey + kind.group}];
    mixed.insert(mixed.end(), it->second.begin(), it->second.end());
    it = groups.erase(it);
  }
  LightForest forest;
  forest.trees.resize(groups.size());
  std::vector<std::pair<GroupKey, const std::vector<uint32_t>*>> work;
  for (auto& [k, v] : groups) work.emplace_back(k, &v);
  double total = 0;
  for (auto& [k, v] : groups) total += double(v.size());
  Progress progress(options.progress, total);
  // Trees are independent; build them side by side (each builder is itself parallel).
  tbb::parallel_for(size_t(0), work.size(), [&](size_t i) {
    const GroupKey& k = work[i].first;
    const std::vector<uint32_t>& idx = *work[i].second;
    uint64_t seed = options.seed * 0x9E3779B97F4A7C15ull + i;
    LightTree t;
    if (options.builder == TreeBuilder::Course) {
      t = buildCourseTree(lights, idx, k.type, seed);
      progress.add(double(idx.size()));
    } else {
      // c weights the normal cone for lights whose emission depends on direction.
      float c = 0;
      if (k.type == LightType::Oriented || k.type == LightType::Spot) {
        c = options.sceneDiagonal;
        if (!(c > 0)) {
          Bounds3 b;
          for (uint32_t li : idx) b.extend(lights.lights[li].position);
          c = b.diagonal();
        }
      }
      t = buildAgglomerativeTree(lights, idx, k.type, c, seed, std::max<size_t>(options.exactLimit, 2), &progress);
      // The builder fills the preorder and the moments.
      if (options.courseData) computeCourseData(lights, t);
    }
    if (t.preorder.size() != t.nodes.size()) computePreorder(t);
    if (k.type == LightType::Directional) computeDirectionCones(lights, t);
    t.type = k.type;
    if (k.group < kMixedKey) {
      t.group = uint16_t(k.group);
      t.bound = lights.groups[t.group];
    } else {
      t.mixedGroups = true;
      t.group = lights.lights[idx.front()].group;
      t.bound = t.boundLow = lights.groups[t.group];
      // The lights come group after group (concatenated above): each group once.
      uint16_t last = t.group;
      for (uint32_t li : idx) {
        if (lights.lights[li].group == last) continue;
        last = lights.lights[li].group;
        t.bound = upperEnvelope(t.bound, lights.groups[last]);
        t.boundLow = lowerEnvelope(t.boundLow, lights.groups[last]);
      }
    }
    forest.trees[i] = std::move(t);
  });
  progress.finish();
  forest.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return forest;
}

}  // namespace lc::lightcuts
