#include "lightcuts/light_tree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>
#include <stdexcept>

#include "core/error.h"
#include "lightcuts/cluster.h"

namespace lc::lightcuts {

size_t LightForest::memoryBytes() const {
  size_t b = 0;
  for (const LightTree& t : trees)
    b += t.nodes.size() * sizeof(LightNode) + t.course.size() * sizeof(CourseNodeData) +
         t.moments.size() * sizeof(NodeMoments);
  return b;
}

size_t LightForest::nodeCount() const {
  size_t n = 0;
  for (const LightTree& t : trees) n += t.empty() ? 0 : 2 * size_t(t.lightTotal) - 1;
  return n;
}

namespace {
// computeDirectionCones widens each cone by this angle (radians).
constexpr double kConeMargin = 1e-3;
Vec3d unitd(const Vec3d& v) {
  double l = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return l > 0 ? v / l : Vec3d(0, 0, 1);
}
// The stored cosine of a cone of half-angle `angle`, widened (computeDirectionCones).
float widenedCos(double angle) {
  const double widened = angle + kConeMargin;
  return widened >= kPi ? -1.0f : std::nextafter(float(std::cos(widened)), -1.0f);
}
}  // namespace

void LightTree::directionalLeafCone(const Light& l, LightNode& n) {
  n.axis = unitd(Vec3d(l.direction)).toFloat();
  n.cosHalfAngle = widenedCos(0);
}

std::vector<NodeRef> LightTree::preorderNodes() const {
  std::vector<NodeRef> out;
  if (empty()) return out;
  out.reserve(2 * size_t(lightTotal) - 1);
  std::vector<NodeRef> stack{root};
  while (!stack.empty()) {
    NodeRef r = stack.back();
    stack.pop_back();
    out.push_back(r);
    if (isLeafRef(r)) continue;
    stack.push_back(nodes[r].right(r));
    stack.push_back(nodes[r].left(r));
  }
  return out;
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

using detail::MomentSums;

void setMeans(NodeMoments& m, const MomentSums& s) {
  if (s.w > 0) {
    m.centroid = (s.pos / s.w).toFloat();
    m.meanAxis = (s.axis / s.w).toFloat();
  } else {
    m.centroid = (s.posU / s.n).toFloat();
    m.meanAxis = (s.axisU / s.n).toFloat();
  }
}

}  // namespace

namespace detail {

namespace {

// A leaf's sums.
MomentSums leafSums(const LightSet& lights, const LightTree& tree, NodeRef r) {
  const Light& l = lights.lights[leafLight(r)];
  const LightNode n = tree.leafNode(l, leafLight(r));
  MomentSums s;
  s.w = lum(n.intensity);
  s.n = 1;
  s.posU = Vec3d(n.lo);
  s.axisU = Vec3d(tree.type == LightType::Directional ? -n.lo : l.direction);
  s.pos = s.posU * s.w;
  s.axis = s.axisU * s.w;
  return s;
}

// subtreeMoments of an inner node with nothing known: its subtree's inner nodes fill the
// slots from `top` on (preorder), and a node's children come after it, so the slots read
// back to front meet every child before its parent. The nodes are read in order and the
// leaves' lights fetched kAhead nodes ahead: walked depth first, the sums waited on each
// leaf's light, a cache miss in a light array of hundreds of megabytes (perf at 8.1M
// lights: two thirds of the pass on that one load; now 21% fewer samples). Each node adds its right child's sums
// to its left child's, as the walk does: the same sums, bit for bit.
MomentSums slotMoments(const LightSet& lights, LightTree& tree, NodeRef top) {
  const uint32_t count = tree.nodes[top].lights() - 1;  // the subtree's inner nodes
  static thread_local std::vector<MomentSums> sums;     // by slot - top
  sums.resize(count);
  constexpr uint32_t kAhead = 32;
  auto fetchLeaves = [&](uint32_t k) {
    const LightNode& a = tree.nodes[top + k];
    if (a.leftIsLeaf()) __builtin_prefetch(&lights.lights[leafLight(a.left(top + k))]);
    if (a.rightIsLeaf()) __builtin_prefetch(&lights.lights[leafLight(a.right(top + k))]);
  };
  for (uint32_t k = count; k-- > count - std::min(count, kAhead);) fetchLeaves(k);
  for (uint32_t k = count; k-- > 0;) {
    if (k >= kAhead) fetchLeaves(k - kAhead);
    const NodeRef r = top + k;
    const LightNode& n = tree.nodes[r];
    const NodeRef left = n.left(r), right = n.right(r);
    MomentSums s = isLeafRef(left) ? leafSums(lights, tree, left) : sums[left - top];
    s.add(isLeafRef(right) ? leafSums(lights, tree, right) : sums[right - top]);
    setMeans(tree.moments[r], s);
    sums[k] = s;
  }
  return sums[0];
}

}  // namespace

MomentSums subtreeMoments(const LightSet& lights, LightTree& tree, NodeRef top,
                          const std::unordered_map<NodeRef, MomentSums>* known) {
  if (!known && !isLeafRef(top)) return slotMoments(lights, tree, top);
  // Post-order with an explicit stack (chains of merges can be deep).
  BigVector<NodeMoments>& m = tree.moments;
  std::vector<std::pair<NodeRef, bool>> stack{{top, false}};  // node, children done
  std::vector<MomentSums> done;  // the finished subtrees whose parent is not
  while (!stack.empty()) {
    auto [r, expanded] = stack.back();
    stack.pop_back();
    if (!expanded && known) {
      auto k = known->find(r);
      if (k != known->end()) {
        done.push_back(k->second);
        continue;
      }
    }
    if (isLeafRef(r)) {
      done.push_back(leafSums(lights, tree, r));
      continue;
    }
    const LightNode& n = tree.nodes[r];
    if (!expanded) {
      stack.emplace_back(r, true);
      stack.emplace_back(n.right(r), false);
      stack.emplace_back(n.left(r), false);
      continue;
    }
    MomentSums b = done.back();
    done.pop_back();
    done.back().add(b);  // the left child's sums become this node's
    setMeans(m[r], done.back());
  }
  return done.back();
}

}  // namespace detail

void computeMoments(const LightSet& lights, LightTree& tree) {
  // The luminance-weighted sums of each subtree's positions and axes, in double, divided
  // once per node: a node's mean is exact to float rounding however many lights it holds
  // and however deep (a mean of the children's float means loses ~1e-7 per level, which a
  // long chain of merges adds up). A subtree of zero weight takes the plain mean. Each
  // node's sums are its left child's plus its right child's, so the subtrees below the
  // top levels are summed in parallel to the same values. Memory: the tree's depth.
  BigVector<NodeMoments>& m = tree.moments;
  m.resize(tree.nodes.size());  // one per inner node, each written below
  if (tree.empty() || isLeafRef(tree.root)) return;
  // Top levels: split down to subtrees of at most kTask lights.
  constexpr uint32_t kTask = 1u << 14;
  std::vector<NodeRef> tasks;
  std::vector<NodeRef> stack{tree.root};
  while (!stack.empty()) {
    NodeRef r = stack.back();
    stack.pop_back();
    if (tree.lightCount(r) <= kTask) {
      tasks.push_back(r);
      continue;
    }
    const LightNode& n = tree.nodes[r];
    stack.push_back(n.right(r));
    stack.push_back(n.left(r));
  }
  std::vector<detail::MomentSums> sums(tasks.size());
  tbb::parallel_for(size_t(0), tasks.size(),
                    [&](size_t k) { sums[k] = detail::subtreeMoments(lights, tree, tasks[k]); });
  std::unordered_map<NodeRef, detail::MomentSums> known;
  for (size_t k = 0; k < tasks.size(); ++k) known.emplace(tasks[k], sums[k]);
  detail::subtreeMoments(lights, tree, tree.root, &known);
}

void computeCourseData(const LightSet& lights, LightTree& tree) {
  if (tree.moments.size() != tree.nodes.size()) computeMoments(lights, tree);
  tree.course = courseNodeData(lights, tree);
}

std::vector<CourseNodeData> courseNodeData(const LightSet& lights, const LightTree& tree) {
  // Bottom-up (slots in reverse: children after parents), from the moments. The mean
  // distance to the centroid is exact for leaves and bounded above through the triangle
  // inequality for inner nodes; the seed builder overwrites it with exact values.
  std::vector<CourseNodeData> sd(tree.nodes.size(), CourseNodeData{});
  std::vector<float> spread(tree.nodes.size(), 0.0f);
  auto chroma = [](const Color& c) {
    double s = double(c.x) + c.y + c.z;  // in double: the float sum may overflow
    return s > 0 ? Color(float(c.x / s), float(c.y / s), float(c.z / s)) : Color(1.0f / 3);
  };
  // A child's data, intensity and colour spread: a leaf's from its light.
  struct Child {
    CourseNodeData d;
    Color intensity;
    float spread;
  };
  auto child = [&](NodeRef r) {
    if (!isLeafRef(r)) return Child{sd[r], tree.nodes[r].intensity, spread[r]};
    const NodeMoments mo = tree.momentsOf(lights, r);
    return Child{CourseNodeData{mo.centroid, mo.meanAxis, 0}, tree.node(lights, r).intensity, 0.0f};
  };
  for (size_t i = tree.nodes.size(); i-- > 0;) {
    const LightNode& n = tree.nodes[i];
    CourseNodeData& d = sd[i];
    const NodeMoments& mo = tree.moments[i];
    d.position = mo.centroid;
    const Child ca = child(n.left(NodeRef(i))), cb = child(n.right(NodeRef(i)));
    const CourseNodeData& da = ca.d;
    const CourseNodeData& db = cb.d;
    d.direction = length2(mo.meanAxis) > 0 ? normalize(mo.meanAxis) : da.direction;
    // Relative weights (in double: luminances near FLT_MAX would overflow their sum).
    double la = lum(ca.intensity), lb = lum(cb.intensity);
    float wa = 0.5f, wb = 0.5f, w = 1;
    if (la + lb > 0) wa = float(la / (la + lb)), wb = float(lb / (la + lb));
    float meanDist = (wa * (da.error / (1 + ca.spread) + length(da.position - d.position)) +
                      wb * (db.error / (1 + cb.spread) + length(db.position - d.position))) / w;
    Color cm = chroma(n.intensity);
    Vec3 xa = vabs(chroma(ca.intensity) - cm), xb = vabs(chroma(cb.intensity) - cm);
    spread[i] = (wa * (ca.spread + xa.x + xa.y + xa.z) + wb * (cb.spread + xb.x + xb.y + xb.z)) / w;
    d.error = meanDist * (1 + spread[i]);
  }
  return sd;
}

void computeDirectionCones(const LightSet& lights, LightTree& tree) {
  // Bottom-up in double (slots in reverse: children after parents): each inner node's cone
  // is the smallest cone holding its children's (as coneUnion), so a node's cone holds
  // every light below it. A float cosine cannot tell half-angles below ~3.5e-4 apart (cos
  // rounds to 1), so each node stores cos(half-angle + kConeMargin), rounded down: the angle
  // it stands for is never too small. A leaf's cone (LightTree::leafNode) is its light's
  // direction, widened alike.
  const size_t n = tree.nodes.size();
  std::vector<Vec3d> axis(n);
  std::vector<double> angle(n);
  auto dotd = [](const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  auto cone = [&](NodeRef r, Vec3d& ax, double& an) {
    if (isLeafRef(r)) {
      ax = unitd(Vec3d(lights.lights[leafLight(r)].direction));
      an = 0;
    } else {
      ax = axis[r];
      an = angle[r];
    }
  };
  for (size_t i = n; i-- > 0;) {
    LightNode& nd = tree.nodes[i];
    Vec3d a, b;
    double ta, tb;
    cone(nd.left(NodeRef(i)), a, ta);
    cone(nd.right(NodeRef(i)), b, tb);
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
        axis[i] = unitd(a * std::cos(phi) + t * (std::sin(phi) / tl));
        angle[i] = to;
      }
    }
    nd.axis = axis[i].toFloat();
    nd.cosHalfAngle = widenedCos(angle[i]);
  }
}

std::vector<LightGroupList> lightsByGroup(const LightSet& lights, size_t block) {
  // (One map lookup per light, and lists grown one index at a time, took 0.4 s of one
  // thread at 8.1M lights.)
  const size_t n = lights.lights.size();
  block = std::max<size_t>(block, 1);
  const size_t blocks = (n + block - 1) / block;
  std::vector<std::map<GroupKey, std::vector<uint32_t>>> parts(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    auto& part = parts[b];
    std::vector<uint32_t>* last = nullptr;  // the previous light's list: runs share one
    GroupKey lastKey{};
    for (size_t i = b * block; i < std::min(n, (b + 1) * block); ++i) {
      const Light& l = lights.lights[i];
      if (!(luminance(l.intensity) > 0)) continue;
      const GroupKey k{l.type, l.group};
      if (!last || k.type != lastKey.type || k.group != lastKey.group) {
        last = &part[k];
        lastKey = k;
      }
      last->push_back(uint32_t(i));
    }
  });
  std::map<GroupKey, size_t> sizes;
  for (const auto& part : parts)
    for (const auto& [k, v] : part) sizes[k] += v.size();
  std::vector<LightGroupList> out;
  std::map<GroupKey, size_t> at;
  for (const auto& [k, size] : sizes) {
    at[k] = out.size();
    out.push_back(LightGroupList{k.type, uint16_t(k.group), {}});
    out.back().lights.reserve(size);
  }
  for (auto& part : parts) {
    for (const auto& [k, v] : part) {
      std::vector<uint32_t>& dst = out[at[k]].lights;
      dst.insert(dst.end(), v.begin(), v.end());
    }
    std::map<GroupKey, std::vector<uint32_t>>().swap(part);  // freed as it is joined
  }
  return out;
}

LightForest buildLightForest(const LightSet& lights, const TreeBuildOptions& options) {
  auto t0 = std::chrono::steady_clock::now();
  std::map<GroupKey, std::vector<uint32_t>> groups;
  for (LightGroupList& g : lightsByGroup(lights)) groups[GroupKey{g.type, g.group}] = std::move(g.lights);
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
  if (lights.lights.size() > kMaxTreeLights)
    throw Error("more than " + std::to_string(kMaxTreeLights) + " lights: a light tree names its lights in 30 bits");
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
      // The builder fills the moments.
      if (options.courseData) computeCourseData(lights, t);
    }
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
