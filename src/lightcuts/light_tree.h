// Light trees: binary trees of light clusters. Each inner node stores what the Lightcuts
// error bounds need (bounding box, cone of light normals, summed intensity, a
// representative light) and, in a parallel array, the first moments that the first-order
// estimate needs; a leaf is its light, stored nowhere else (NodeRef). Inner nodes sit in
// preorder, and walks that need a node's preorder position (reconstruction cuts) carry it
// down. What the seed's traversal needs (intensity-weighted centroid and direction, and its
// error radius) the seed builder stores; for other trees the seed's evaluator computes it
// when it is made.
//
// Two builders:
//   Agglomerative (Walter et al. 2005, built the fast way of Walter et al. 2008): greedily
//     merge the pair whose union minimises I * (alpha^2 + c^2 (1 - cos beta)^2), found by
//     nearest-neighbour search in a k-d tree over clusters and a heap of best pairs.
//   Course (the course project's k-d split): recursive split over x, y, z at the position that
//     balances the halves and falls at the largest gap in position and colour.
// One tree per (light type, light group): clusters never mix attenuation or falloff.
#pragma once

#include <limits>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/huge_pages.h"
#include "core/math.h"
#include "core/progress.h"
#include "core/light.h"

namespace lc::lightcuts {

// A node as its readers name it: an inner node by its slot (how many inner nodes come
// before it in preorder: the root's is 0, a left child's its parent's + 1), a leaf by its
// light's index with kLeafRef set. A tree stores only its inner nodes; a leaf is its light.
using NodeRef = uint32_t;
constexpr NodeRef kLeafRef = 1u << 31;
inline bool isLeafRef(NodeRef r) { return (r & kLeafRef) != 0; }
inline NodeRef leafRef(uint32_t light) { return kLeafRef | light; }
inline uint32_t leafLight(NodeRef r) { return r & ~kLeafRef; }

// 64 bytes: one cache line. Stored for inner nodes; a leaf's is made from its light
// (LightTree::node), its children fields then 0.
struct LightNode {
  Vec3 lo, hi;          // bounds of light positions (directional trees: of directions to the light)
  Vec3 axis;            // cone of light normals/axes (oriented, spot), of the lights' travel
                        // directions (directional: computeDirectionCones); unit
  float cosHalfAngle;   // cone half-angle's cosine; -1 = all directions
  Color intensity;      // summed RGB intensity of the cluster
  uint32_t rep;         // representative light (index into LightSet::lights)
  // The children, packed so that a node alone says where both are and how many lights it
  // holds (every refinement reads the count, for the visibility probes): a leaf child by
  // its light; an inner left child is the next slot, an inner right child the slot after
  // the left subtree's inner nodes (self + left count). a = left leaf ? its light : the
  // left subtree's light count, with kLeftLeaf and kRightLeaf; b = right leaf ? its light :
  // this node's light count.
  uint32_t a = 0, b = 0;

  static constexpr uint32_t kLeftLeaf = 1u << 31, kRightLeaf = 1u << 30, kValue = kRightLeaf - 1;
  bool leftIsLeaf() const { return (a & kLeftLeaf) != 0; }
  bool rightIsLeaf() const { return (a & kRightLeaf) != 0; }
  uint32_t leftLights() const { return leftIsLeaf() ? 1 : a & kValue; }
  uint32_t lights() const { return rightIsLeaf() ? leftLights() + 1 : b; }  // inner nodes only
  // The children of this node, stored at slot `self`.
  NodeRef left(NodeRef self) const { return leftIsLeaf() ? leafRef(a & kValue) : self + 1; }
  NodeRef right(NodeRef self) const { return rightIsLeaf() ? leafRef(b) : self + leftLights(); }
  // Preorder positions of the children, from this node's.
  static uint32_t leftPre(uint32_t pre) { return pre + 1; }
  uint32_t rightPre(uint32_t pre) const { return pre + 2 * leftLights(); }
  // Sets the children: each a light (leaf) or a subtree of `count` lights.
  void setChildren(bool leftLeaf, uint32_t leftLightOrCount, bool rightLeaf, uint32_t rightLight,
                   uint32_t count) {
    a = (leftLightOrCount & kValue) | (leftLeaf ? kLeftLeaf : 0) | (rightLeaf ? kRightLeaf : 0);
    b = rightLeaf ? rightLight : count;
  }
};
static_assert(sizeof(LightNode) == 64, "LightNode should fill one cache line");

// A light's intensity in a node: clamped as inner nodes' sums are, so that a light of
// infinite power keeps a finite node intensity.
inline Color leafIntensity(const Light& l) {
  return vmin(l.intensity, Color(std::numeric_limits<float>::max()));
}

// Light indices and light counts fit LightNode's 30-bit fields: buildLightForest refuses a
// light set of more lights (40 GB of them).
constexpr size_t kMaxTreeLights = LightNode::kValue;

// Per-node data of the seed's traversal: a synthetic light at the intensity-weighted
// centroid, and the node's error radius.
struct CourseNodeData {
  Vec3 position;   // weighted centroid (directional: weighted mean direction)
  Vec3 direction;  // weighted mean normal/axis, unit
  float error;     // weighted mean distance to the centroid, scaled by the colour spread
};

// Per-node first moments of the cluster's lights, weighted by luminance: what the
// first-order estimate of a cluster (estimate.h) subtracts from its representative's.
struct NodeMoments {
  Vec3 centroid;  // mean position (directional trees: mean direction toward the light)
  Vec3 meanAxis;  // mean normal/axis, not normalised (oriented and spot lights)
};

struct LightTree {
  LightType type = LightType::Omni;
  uint16_t group = 0;  // its lights' group (a tree that mixes groups: its first light's)
  // What the tree's bounds use: its lights' group or, for a tree that mixes groups
  // (mixedGroups: a scene with more than kMaxGroupTrees groups of one kind, say spots that
  // each have their own cone), their upper envelope (core/light.h), which bounds every
  // light's model from above; its lower bounds use their lower envelope (boundLow), and it
  // has no first-order estimates. A light's own contribution always uses its own group.
  LightGroup bound;
  LightGroup boundLow;  // mixed trees: the groups' lower envelope, for lower bounds
  bool mixedGroups = false;
  uint32_t lightTotal = 0;     // lights in the tree
  BigVector<LightNode> nodes;  // the inner nodes by slot (preorder): nodes[0] is the root
  // Per inner node, by slot: the seed builder fills it; agglomerative trees leave it empty
  // (unless TreeBuildOptions::courseData) and makeCourseCuts computes it on demand.
  std::vector<CourseNodeData> course;
  // Per inner node, by slot. A leaf's moments are its light's (momentsOf).
  BigVector<NodeMoments> moments;

  NodeRef root = 0;  // slot 0, or a tree of one light: that light's leaf

  bool empty() const { return lightTotal == 0; }
  // Node r's LightNode: stored for an inner node, made from the light for a leaf.
  LightNode node(const LightSet& lights, NodeRef r) const {
    return isLeafRef(r) ? leafNode(lights.lights[leafLight(r)], leafLight(r)) : nodes[r];
  }
  // A leaf's node: the light's point, its cone (an exact cone for oriented and spot lights;
  // directional trees: computeDirectionCones' cone of a single direction), its intensity.
  // Inline: the reconstruction walk and the moments make one per leaf.
  LightNode leafNode(const Light& l, uint32_t index) const {
    LightNode n;
    n.intensity = leafIntensity(l);
    n.rep = index;
    if (type == LightType::Directional) {
      n.lo = n.hi = -l.direction;
      directionalLeafCone(l, n);
    } else {
      n.lo = n.hi = l.position;
      const bool cone = l.type == LightType::Oriented || l.type == LightType::Spot;
      n.axis = cone ? l.direction : Vec3(0, 0, 1);
      n.cosHalfAngle = cone ? 1.0f : -1.0f;
    }
    return n;
  }
  static void directionalLeafCone(const Light& l, LightNode& n);
  // Node r's moments: stored for inner nodes, made from the light for a leaf.
  NodeMoments momentsOf(const LightSet& lights, NodeRef r) const {
    if (!isLeafRef(r)) return moments[r];
    const Light& l = lights.lights[leafLight(r)];
    return NodeMoments{l.type == LightType::Directional ? -l.direction : l.position, l.direction};
  }
  // How many lights node r holds.
  uint32_t lightCount(NodeRef r) const { return isLeafRef(r) ? 1 : nodes[r].lights(); }
  // Node r's representative light.
  uint32_t repOf(NodeRef r) const { return isLeafRef(r) ? leafLight(r) : nodes[r].rep; }
  // Every node in preorder (a node's preorder position is its index here): for tests and
  // for walks that want the whole tree.
  std::vector<NodeRef> preorderNodes() const;
};

// Course: the course project's k-d split (`--tree seed` or `course`).
enum class TreeBuilder { Agglomerative, Course };
// Its names (core/enum_names.h: the first of a value its name, then aliases), read by the
// functions below and by render --tree.
inline constexpr EnumName<TreeBuilder> kTreeBuilderNames[] = {
    {TreeBuilder::Agglomerative, "walter", "agglomerative"},
    {TreeBuilder::Agglomerative, "agglomerative"},
    {TreeBuilder::Course, "seed", "k-d split"},
    {TreeBuilder::Course, "course"}};

// Lights of one kind (type, diffuseOnly, isVpl) in more groups than this share one tree
// (LightTree::mixedGroups): a tree per group would leave thousands of one-light trees, every
// one of them in every cut.
constexpr size_t kMaxGroupTrees = 16;

struct TreeBuildOptions {
  TreeBuilder builder = TreeBuilder::Agglomerative;
  uint64_t seed = 1;  // representative choice
  // Agglomerative: light sets up to this size are clustered exactly (greedy); larger ones
  // bottom-up in Morton-ordered groups first (see agglomerative_build.cpp).
  size_t exactLimit = 8192;
  // c of the metric for oriented and spot lights: the scene's diagonal (Walter et al.). 0 =
  // the diagonal of the tree's own lights (for callers that know no scene).
  float sceneDiagonal = 0;
  ProgressFn progress = {};  // called with the share of lights clustered (core/progress.h)
  // Agglomerative trees: fill LightTree::seed as well (56 bytes per light that only
  // --method seed reads; makeCourseCuts computes the same data when it is missing).
  bool courseData = false;
};

struct LightForest {
  std::vector<LightTree> trees;
  double buildSeconds = 0;
  size_t memoryBytes() const;
  size_t nodeCount() const;
};

// Builds one tree per (type, group) over the lights with non-zero intensity.
LightForest buildLightForest(const LightSet& lights, const TreeBuildOptions& options = {});

// Throws lc::Error for another name.
inline TreeBuilder parseTreeBuilder(std::string_view name) {
  return parseEnum(kTreeBuilderNames, name, "light tree builder");
}
inline const char* treeBuilderName(TreeBuilder b) { return enumName(kTreeBuilderNames, b); }

// ---- building blocks, exposed for tests ----

// Smallest cone containing both cones (pbrt-v4's DirectionCone union).
void coneUnion(const Vec3& a, float cosA, const Vec3& b, float cosB, Vec3& axis, float& cosOut);

// The agglomerative metric of a cluster: I * (diag^2 + c^2 (1 - cos beta)^2). Computed in
// double and clamped to the largest float, so that huge intensities or extents give a
// large finite value rather than inf (or NaN from inf * 0).
inline float clusterMetric(float intensity, const Vec3& lo, const Vec3& hi, float cosHalfAngle,
                           float c) {
  double ex = double(hi.x) - lo.x, ey = double(hi.y) - lo.y, ez = double(hi.z) - lo.z;
  double a = 1 - double(cosHalfAngle), cc = double(c);
  double m = double(intensity) * (ex * ex + ey * ey + ez * ez + cc * cc * a * a);
  return m >= double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::max() : float(m);
}

// The lights with non-zero intensity of each (type, group), each list in index order and
// the lists by (type, group): gathered `block` lights at a time in parallel, then joined
// block after block (buildLightForest's first step; the same lists for any block size).
struct LightGroupList {
  LightType type;
  uint16_t group;
  std::vector<uint32_t> lights;
};
std::vector<LightGroupList> lightsByGroup(const LightSet& lights, size_t block = size_t(1) << 20);

// Builders over a list of light indices of one type and group (used by buildLightForest).
LightTree buildAgglomerativeTree(const LightSet& lights, const std::vector<uint32_t>& indices,
                                 LightType type, float coneWeight, uint64_t seed,
                                 size_t exactLimit = 8192, Progress* progress = nullptr);
LightTree buildCourseTree(const LightSet& lights, const std::vector<uint32_t>& indices, LightType type,
                        uint64_t seed);

// Directional trees: sets each node's cone (axis, cosHalfAngle) to one holding its
// lights' travel directions, a little wider than needed so that float rounding never makes
// it too narrow (buildLightForest calls it; the builders leave these trees without cones).
void computeDirectionCones(const LightSet& lights, LightTree& tree);

// Fills LightTree::moments from the finished nodes (the seed builder's trees; the
// agglomerative builder sums them as it lays the tree out, to the same values).
void computeMoments(const LightSet& lights, LightTree& tree);

// Fills LightTree::course from the finished nodes and their moments (centroids, mean
// directions, errors).
void computeCourseData(const LightSet& lights, LightTree& tree);
// The same data, for a tree that has its moments, without touching the tree.
std::vector<CourseNodeData> courseNodeData(const LightSet& lights, const LightTree& tree);

}  // namespace lc::lightcuts
