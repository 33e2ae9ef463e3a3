#include "lightcuts/exact_sum.h"

#include <gtest/gtest.h>

#include <vector>

#include "lightcuts/cluster.h"
#include "test_lights.h"

namespace lc::lightcuts {
namespace {

using test_lights::cloud;
using test_lights::point;

// The lights under r, right children first (the order unshadowedSum adds them in), found
// by recursion through the children rather than from the layout of the slots.
void lightsUnder(const LightTree& t, NodeRef r, std::vector<uint32_t>& out) {
  if (isLeafRef(r)) {
    out.push_back(leafLight(r));
    return;
  }
  lightsUnder(t, t.nodes[r].right(r), out);
  lightsUnder(t, t.nodes[r].left(r), out);
}

// At every node of a tree: the sum is the lights' own contributions added one by one,
// and the brightest light is the first of the largest, whatever the subtree's shape (the
// sum reads the lights from the run of slots of the subtree's inner nodes).
TEST(ExactSum, IsTheSumOfTheNodesLightsInAFixedOrder) {
  for (LightType type : {LightType::Omni, LightType::Oriented}) {
    LightSet s = cloud(700, type, 5);
    LightForest f = buildLightForest(s);
    ASSERT_EQ(f.trees.size(), 1u);
    const LightTree& t = f.trees[0];
    for (const Vec3& p : {Vec3(0.3f, 0, -0.2f), Vec3(-1.5f, 1.9f, 1.2f)}) {
      const ShadingPoint sp = point(p);
      size_t checked = 0;
      for (NodeRef r : t.preorderNodes()) {
        std::vector<uint32_t> ls;
        lightsUnder(t, r, ls);
        ASSERT_EQ(ls.size(), size_t(t.lightCount(r)));
        Vec3d want;
        float brightest = 0;
        Vec3 dir;
        for (uint32_t i : ls) {
          const Light& l = s.lights[i];
          Color mg;
          Vec3 wi;
          float dist;
          if (!lightContribution(l, s.groups[l.group], sp, mg, wi, dist)) continue;
          const Color c = mg * leafIntensity(l);
          want += c;
          if (luminance(c) > brightest) brightest = luminance(c), dir = wi;
        }
        const ExactSum e = unshadowedSum(s, t, r, sp);
        const Color w = want.toFloat();
        EXPECT_EQ(e.sum.x, w.x) << "node " << r;
        EXPECT_EQ(e.sum.y, w.y) << "node " << r;
        EXPECT_EQ(e.sum.z, w.z) << "node " << r;
        EXPECT_EQ(e.brightest, brightest) << "node " << r;
        if (brightest > 0) {
          EXPECT_EQ(e.brightestDir, dir) << "node " << r;
        }
        ++checked;
      }
      EXPECT_EQ(checked, size_t(2 * s.lights.size() - 1));
    }
  }
}

// Visibility: the sum as it is when the cluster is known visible (no ray), else one ray
// toward the brightest light, whose answer scales the whole sum.
TEST(ExactSum, WithVisibilitySendsOneRayTowardTheBrightestLight) {
  LightSet s = cloud(64, LightType::Omni, 9);
  LightForest f = buildLightForest(s);
  const LightTree& t = f.trees[0];
  const ShadingPoint sp = point(Vec3(0.1f, 0, 0.2f));
  const ExactSum e = unshadowedSum(s, t, t.root, sp);
  ASSERT_GT(e.brightest, 0.0f);
  struct Half : Visibility {
    Vec3 asked;
    int rays = 0;
    Color operator()(const Vec3& wi, float) override {
      asked = wi;
      ++rays;
      return Color(0.5f);
    }
  };
  Half vis;
  EvalStats st;
  EXPECT_EQ(withVisibility(e, vis, st, true), e.sum);
  EXPECT_EQ(vis.rays, 0);
  const Color half = withVisibility(e, vis, st, false);
  EXPECT_EQ(vis.rays, 1);
  EXPECT_EQ(st.shadowRays, 1u);
  EXPECT_EQ(vis.asked, e.brightestDir);
  EXPECT_EQ(half, e.sum * 0.5f);
}

}  // namespace
}  // namespace lc::lightcuts
