// ShadowRays: where a shadow ray leaves its surface and where it stops short of its light.
#include "render/tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "io/ray_parser.h"
#include "lightcuts/evaluator.h"
#include "lightcuts/light_tree.h"
#include "scene/scene.h"
#include "test_lights.h"

namespace lc::render {
namespace {

// Two walls 1 apart facing each other (x = 0, lit side +x; x = 1, lit side -x), 20 units
// tall and deep, each two triangles.
std::unique_ptr<scene::Scene> facingWalls() {
  return scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
material = { name = white; diffuse = (0.5, 0.5, 0.5); }
trimesh { material = white; points = ((0, -10, -10), (0, 10, -10), (0, 10, 10), (0, -10, 10));
          faces = ((0, 1, 2), (0, 2, 3)); }
trimesh { material = white; points = ((1, -10, -10), (1, -10, 10), (1, 10, 10), (1, 10, -10));
          faces = ((0, 1, 2), (0, 2, 3)); }
)",
                                                "walls.ray", ""));
}

// A light that lies on the facing wall (a VPL: where its path hit) is visible from every
// point of the other wall, whatever the slant. The ray used to aim at the light moved off
// the point's own surface (by its normal times epsilon), which here is behind the facing
// wall; ending 3 epsilon short along the ray brought it back in front only where the ray
// met that wall steeply (cos above about 1/2), so lights seen at a slant were hidden, in
// brute force as in lightcuts: the Cornell box's red wall lit none of the tall block's side.
TEST(ShadowRays, ALightOnTheFacingSurfaceIsVisibleAtAnySlant) {
  auto scene = facingWalls();
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(0.5f, 0.3f, -0.2f), Vec3(-1, 0, 0)}, h));
  ASSERT_NEAR(h.p.x, 0, 1e-6);
  ShadowRays vis(*scene, h);
  int hidden = 0, total = 0;
  for (float y : {0.0f, 0.5f, 1.0f, 2.0f, 3.0f, 5.0f, 8.0f})
    for (float z : {-3.0f, 0.0f, 4.0f}) {
      const Vec3 light(1, y, z);
      const Vec3 d = light - h.p;
      const float dist = length(d);
      ++total;
      int blocker;
      float tHit;
      const bool seen = vis(d / dist, dist).x == 1;
      const bool traced = vis.trace(d / dist, dist, blocker, tHit).x == 1;
      EXPECT_EQ(seen, traced) << y << " " << z;
      hidden += !seen;
    }
  EXPECT_EQ(hidden, 0) << "of " << total << " lights on the facing wall";
}

// And the other way: a light just behind the facing wall stays hidden, at any slant.
TEST(ShadowRays, ALightBehindTheFacingSurfaceIsHidden) {
  auto scene = facingWalls();
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(0.5f, 0.3f, -0.2f), Vec3(-1, 0, 0)}, h));
  ShadowRays vis(*scene, h);
  for (float y : {0.0f, 1.0f, 3.0f, 8.0f}) {
    const Vec3 light(1.05f, y, 0);
    const Vec3 d = light - h.p;
    const float dist = length(d);
    EXPECT_EQ(vis(d / dist, dist).x, 0) << y;
  }
}

// Lights so far away that the squared distance overflows a float still get a ray along
// their direction: one beyond the facing wall is hidden, one past its edge is seen.
TEST(ShadowRays, FarLightsAreTracedAlongTheirDirection) {
  auto scene = facingWalls();
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(0.5f, 0.3f, -0.2f), Vec3(-1, 0, 0)}, h));
  ShadowRays vis(*scene, h);
  const float far = 1e25f;
  EXPECT_EQ(vis(normalize(Vec3(1, 0.1f, 0)), far).x, 0);
  EXPECT_EQ(vis(normalize(Vec3(0.02f, 1, 0)), far).x, 1);
}

// The box a probe asks for (Visibility::blockerBox): every ray that trace() finds stopped
// by a convex shape passes through it before the hit; none for a shape that is not convex.
TEST(ShadowRays, ABlockersBoxHoldsEveryHitOnIt) {
  auto scene = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
material = { name = white; diffuse = (0.5, 0.5, 0.5); }
translate(0, 0, -0.05, scale(20, 20, 0.1, box { material = white; }))
translate(0.3, -0.2, 2, rotate(1, 1, 0, 0.6, scale(1.5, 0.2, 0.4, box { material = white; })))
translate(-1, 1, 3, sphere { material = white; })
trimesh { material = white; points = ((-5, -5, 6), (5, -5, 6), (0, 5, 6)); faces = ((0, 1, 2)); }
)",
                                                      "blockers.ray", ""));
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(0, 0, 1), Vec3(0, 0, -1)}, h));
  ShadowRays vis(*scene, h);
  int hits[4] = {};
  for (int i = 0; i < 400; ++i) {
    const Vec3 target(float(i % 20) * 0.5f - 5.0f, float(i / 20) * 0.5f - 5.0f, 7.0f);
    const Vec3 d = target - h.p;
    const float dist = length(d);
    int blocker;
    float tHit;
    vis.trace(d / dist, dist, blocker, tHit);
    if (blocker < 0) continue;
    ASSERT_LT(blocker, 4);
    ++hits[blocker];
    Vec3 lo, hi;
    ASSERT_TRUE(vis.blockerBox(blocker, lo, hi)) << blocker;
    const Vec3 q = h.p + d / dist * tHit;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(q[a], lo[a]) << blocker;
      EXPECT_LE(q[a], hi[a]) << blocker;
    }
  }
  EXPECT_GT(hits[1], 0);  // the turned box
  EXPECT_GT(hits[2], 0);  // the sphere
  Vec3 lo, hi;
  EXPECT_FALSE(vis.blockerBox(lightcuts::Visibility::kUnknownBlocker, lo, hi));
  EXPECT_FALSE(vis.blockerBox(lightcuts::Visibility::kVisible, lo, hi));
  EXPECT_FALSE(vis.blockerBox(99, lo, hi));
}

// A room modelled as one solid box, seen from within: a probe toward lights inside it, past
// a lamp outside it that the box hides, is left to the rays (a segment from inside a solid
// crosses no surface); toward a cluster behind a box standing in the room it is decided.
TEST(ShadowRays, ProbesFromInsideASolidAreLeftToTheRays) {
  auto scene = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
material = { name = white; diffuse = (0.5, 0.5, 0.5); }
scale(10, 4, 10, translate(0, 0.5, 0, box { material = white; }))
translate(0, 1, -3, scale(2, 2, 0.2, box { material = white; }))
)",
                                                      "room.ray", ""));
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(0, 2, 2), Vec3(0, -1, 0)}, h));
  ASSERT_NEAR(h.p.y, 0, 1e-5);
  ShadowRays vis(*scene, h);
  auto dirsTo = [&](const Vec3& lo, const Vec3& hi, Vec3* dirs, float& dMin) {
    dMin = kInf;
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
      dirs[k] = normalize(c - h.p);
      dMin = std::min(dMin, length(c - h.p));
    }
  };
  Vec3 dirs[8];
  float dMin;
  // Lights in the room, above the point: the room's box must not claim them.
  dirsTo(Vec3(-0.3f, 2.5f, 1.7f), Vec3(0.3f, 3.0f, 2.3f), dirs, dMin);
  EXPECT_EQ(vis.blocksAll(0, dirs, 8, dMin), -1);
  // A cluster behind the standing box (shape 1), seen from the floor in front of it.
  dirsTo(Vec3(-0.2f, 0.8f, -4.0f), Vec3(0.2f, 1.2f, -3.8f), dirs, dMin);
  EXPECT_EQ(vis.blocksAll(1, dirs, 8, dMin), 1);
  // One whose corners pass above it: not proven.
  dirsTo(Vec3(-0.2f, 2.8f, -4.0f), Vec3(0.2f, 3.2f, -3.8f), dirs, dMin);
  EXPECT_EQ(vis.blocksAll(1, dirs, 8, dMin), 0);
}

// Lightcuts at a zero threshold against brute force, both with the scene's shadow rays,
// at six points of its floor under a cloud of 3,000 lights (2 to 3 units up): at a zero
// threshold every cluster not proven hidden is refined to its lights, so the cut must equal
// brute force, however many clusters the probes prove hidden.
struct ExactCuts {
  lightcuts::EvalStats cut, brute;
};
ExactCuts exactCutsOnTheFloor(const scene::Scene& scene, uint64_t seed) {
  using namespace lightcuts;
  LightSet s = test_lights::cloud(3000, LightType::Omni, seed);
  LightForest f = buildLightForest(s);
  CutOptions o;
  o.errorRatio = 0;
  o.maxCut = 1 << 20;
  o.visibilityProbes = true;
  auto lcut = makeLightcuts(s, f, o);
  auto bf = makeBruteForce(s);
  ExactCuts e;
  scene::Hit h;
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(scene.intersect(scene::Ray{Vec3(0.4f * float(i) - 2.2f, 1, 0.2f * float(i) - 0.4f), Vec3(0, -1, 0)}, h));
    ShadowRays v(scene, h);
    ShadingPoint sp = test_lights::point(h.p);
    const Color want = bf->evaluate(sp, v, e.brute).radiance;
    const Color got = lcut->evaluate(sp, v, e.cut).radiance;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-5f * (want[k] + 1e-6f)) << i;
  }
  return e;
}

// A canopy (a slab with a slanted edge) and a wall written as one triangle mesh (not convex as a whole): a shadow ray
// stopped by it names the flat face it met (scene::PlanarFaces), whose bounds hold the hit,
// and that face decides the probes without rays. With a zero threshold every cluster not
// proven hidden is refined to its lights, so the cut must equal brute force.
TEST(ShadowRays, AMeshsFlatFacesDecideProbesAndTheCutStaysExact) {
  auto scene = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
material = { name = white; diffuse = (0.5, 0.5, 0.5); }
translate(0, -0.05, 0, scale(20, 0.1, 20, box { material = white; }))
trimesh { material = white;
  points = ((-3, 1.4, -3), (0.2, 1.4, -3), (1.5, 1.4, 3), (-3, 1.4, 3),
            (-3, 1.5, -3), (0.2, 1.5, -3), (1.5, 1.5, 3), (-3, 1.5, 3),
            (0.8, 0, -3), (0.9, 0, -3), (0.9, 0, 3), (0.8, 0, 3),
            (0.8, 1.2, -3), (0.9, 1.2, -3), (0.9, 1.2, 3), (0.8, 1.2, 3));
  faces = ((0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5),
           (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7),
           (8, 10, 9), (8, 11, 10), (12, 13, 14), (12, 14, 15), (8, 9, 13), (8, 13, 12), (9, 10, 14),
           (9, 14, 13), (10, 11, 15), (10, 15, 14), (11, 8, 12), (11, 12, 15)); }
)",
                                                      "canopy.ray", ""));
  ASSERT_FALSE(scene->isConvex(1));
  ASSERT_EQ(scene->planarFaces().size(), 12u);
  scene::Hit h;
  ASSERT_TRUE(scene->intersect(scene::Ray{Vec3(-1, 1, 0.3f), Vec3(0, -1, 0)}, h));
  ShadowRays vis(*scene, h);
  const Vec3 d = normalize(Vec3(-1.5f, 2.5f, 0) - h.p);
  int blocker;
  float tHit;
  vis.trace(d, 3, blocker, tHit);
  ASSERT_GE(blocker, 2);  // a face, numbered after the two shapes
  Vec3 lo, hi;
  ASSERT_TRUE(vis.blockerBox(blocker, lo, hi));
  const Vec3 q = h.p + d * tHit;
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(q[a], lo[a]);
    EXPECT_LE(q[a], hi[a]);
  }

  const ExactCuts e = exactCutsOnTheFloor(*scene, 27);
  EXPECT_GT(e.cut.hiddenClusters, 0u);
  EXPECT_EQ(e.cut.probeRays, 0u);
  EXPECT_LT(e.cut.shadowRays, e.brute.shadowRays / 2);
}

// A square (the quadric) turned above the floor is one flat face too: its probes need no
// ray, and the cut still equals brute force at a zero threshold.
TEST(ShadowRays, ASquareDecidesProbesAndTheCutStaysExact) {
  auto scene = scene::Scene::build(io::parseRayString(R"(SBT-raytracer 1.0
material = { name = white; diffuse = (0.5, 0.5, 0.5); }
translate(0, -0.05, 0, scale(20, 0.1, 20, box { material = white; }))
translate(-0.8, 1.45, 0, rotate(0, 1, 0, 0.5, rotate(1, 0, 0, 1.5707963, scale(3, 4, 1, square { material = white; }))))
)",
                                                      "square.ray", ""));
  ASSERT_GE(scene->planarFaces().squareFace(1), 0);
  const ExactCuts e = exactCutsOnTheFloor(*scene, 29);
  EXPECT_GT(e.cut.hiddenClusters, 0u);
  EXPECT_EQ(e.cut.probeRays, 0u);
}

}  // namespace
}  // namespace lc::render
