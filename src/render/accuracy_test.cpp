// End to end: Lightcuts against brute force on the default scene (object-light panel plus
// instant radiosity), the acceptance criterion of the product at a size a test can afford.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <utility>

#include "io/image_metrics.h"
#include "io/ray_parser.h"
#include "lights/object_lights.h"
#include "lights/vpl.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lc::render {
namespace {

struct Loaded {
  std::unique_ptr<scene::Scene> scene;
};

Loaded loadCornell() {
  io::SceneDesc d = io::parseRayFile(testing::scenePath("cornell_box.ray"));
  Loaded l;
  l.scene = scene::Scene::build(d);
  lights::addObjectLights(*l.scene, {});
  lights::VplOptions v;
  v.count = d.instantRadiosity->vpls.value_or(0);
  lights::addVpls(*l.scene, v);
  return l;
}

// (Reconstruction cells here split only where their samples cannot serve a pixel, not for
// disagreeing: at 64 pixels a cell of 4 spans a sixteenth of the box, and most would.)
RenderResult renderWith(const scene::Scene& s, const lightcuts::LightEvaluator& ev, int w, int reconstruct = 0,
                        int coarse = 0) {
  RenderOptions o;
  o.aa = AntiAliasing::Off;  // checked at pixel centres (closed forms, per-pixel comparisons)
  o.width = o.height = w;
  o.reconstructSpacing = reconstruct;
  o.reconstructCoarseSpacing = coarse;
  o.reconstructSplit = 1;
  return render(s, ev, o);
}

// A .ray box of size (sx, sy, sz), turned by rot about y, centred at (x, y, z).
std::string box(float x, float y, float z, float sx, float sy, float sz, float rot, const char* mat) {
  return "translate(" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) + ", rotate(0,1,0," +
         std::to_string(rot) + ", scale(" + std::to_string(sx) + "," + std::to_string(sy) + "," + std::to_string(sz) +
         ", box { material = " + mat + "; })))\n";
}

// A scene from .ray text, with its object lights (luminous materials), and brute force and
// lightcuts (default options) over its lights.
std::unique_ptr<scene::Scene> buildWithObjectLights(const std::string& text) {
  auto s = scene::Scene::build(io::parseRayString(text, "test.ray", "."));
  lights::addObjectLights(*s, {});
  return s;
}

struct Evaluated {
  explicit Evaluated(const std::string& text)
      : scene(buildWithObjectLights(text)),
        brute(lightcuts::makeBruteForce(scene->lights())),
        forest(lightcuts::buildLightForest(scene->lights())),
        lc(lightcuts::makeLightcuts(scene->lights(), forest, lightcuts::CutOptions{})) {}
  Evaluated(Evaluated&&) = delete;  // lc refers to forest
  std::unique_ptr<scene::Scene> scene;
  std::unique_ptr<lightcuts::LightEvaluator> brute;
  lightcuts::LightForest forest;
  std::unique_ptr<lightcuts::LightEvaluator> lc;
};

// Lightcuts' image (full cuts, no antialiasing) against brute force's.
io::ImageMetrics fullCutsAgainstBrute(const Evaluated& e, int width, int height) {
  RenderOptions o;
  o.aa = AntiAliasing::Off;
  o.width = width;
  o.height = height;
  return io::compareImages(render(*e.scene, *e.brute, o).image, render(*e.scene, *e.lc, o).image);
}

// A room of the kind scripts/gen_random_room.py writes: partitions, boxes and a pillar
// among 2,000 point lights, six tenths in clusters under the ceiling and the rest anywhere
// (some close to surfaces, some inside boxes), so that many clusters are partly hidden
// from the points that see their representatives.
std::string randomRoom(uint32_t seed, int lights) {
  std::mt19937 rng(seed);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto g = [&](float sd) { return std::normal_distribution<float>(0, sd)(rng); };
  const float W = 10, H = 4, D = 10;
  const char* wall = "{ diffuse = (0.7, 0.68, 0.65); }";
  std::string t = "SBT-raytracer 1.0\ncamera { position = (-4.2, 2.2, 4.5); look_at = (2, 1.2, -3); aspectratio = 1.5; fov = 60; }\n";
  t += box(0, -0.05f, 0, W, 0.1f, D, 0, "{ diffuse = (0.45, 0.4, 0.35); specular = (0.3, 0.3, 0.3); shininess = 40; }");
  t += box(0, H + 0.05f, 0, W, 0.1f, D, 0, wall);
  t += box(-W / 2 - 0.05f, H / 2, 0, 0.1f, H, D, 0, wall) + box(W / 2 + 0.05f, H / 2, 0, 0.1f, H, D, 0, wall);
  t += box(0, H / 2, -D / 2 - 0.05f, W, H, 0.1f, 0, wall) + box(0, H / 2, D / 2 + 0.05f, W, H, 0.1f, 0, wall);
  for (int i = 0; i < 3; ++i) t += box(u(-3, 3), H * 0.4f, u(-2, 2), 0.15f, H * 0.8f, u(3, 5), 0, "{ diffuse = (0.5, 0.6, 0.4); }");
  for (int i = 0; i < 10; ++i) {
    float sy = u(0.3f, 2);
    t += box(u(-4, 4), sy / 2, u(-4, 4), u(0.3f, 1.5f), sy, u(0.3f, 1.5f), u(0, 3.14f), "{ diffuse = (0.6, 0.5, 0.7); }");
  }
  t += box(u(-3, 3), H / 2, u(-3, 3), 0.4f, H, 0.4f, 0.5f, "{ diffuse = (0.6, 0.6, 0.6); }");
  struct P { float x, y, z; };
  std::vector<P> centres;
  for (int i = 0; i < 16; ++i) centres.push_back({u(-4.5f, 4.5f), u(H * 0.6f, H * 0.95f), u(-4.5f, 4.5f)});
  for (int i = 0; i < lights; ++i) {
    P p;
    if (u(0, 1) < 0.6f) {
      const P& c = centres[size_t(u(0, 15.99f))];
      float r = u(0.1f, 0.6f);
      p = {c.x + g(r), std::min(H - 0.05f, c.y + g(r * 0.5f)), c.z + g(r)};
    } else {
      p = {u(-W / 2 + 0.1f, W / 2 - 0.1f), u(0.3f, H - 0.1f), u(-D / 2 + 0.1f, D / 2 - 0.1f)};
    }
    float i0 = 300.0f / float(lights);
    t += "point_light { position = (" + std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z) +
         "); colour = (" + std::to_string(i0 * u(0.5f, 1)) + "," + std::to_string(i0 * u(0.5f, 1)) + "," +
         std::to_string(i0 * u(0.5f, 1)) + "); }\n";
  }
  return t;
}

// The pixel's error in such a room is the sampling of each cluster's visibility by its
// representative's ray (a partly hidden cluster whose representative is visible comes out
// too bright), which the criterion counts with the point's boundary rate
// (kHiddenSharePerBoundary, evaluator.cpp). Without that term 0.59% of these pixels were
// over 2%; with it none are. (The room is drawn with the standard library's
// distributions, so another library may draw another room.)
TEST(Accuracy, LightcutsWithinTwoPercentInARoomOfPartlyHiddenClusters) {
  Evaluated e(randomRoom(777, 2000));
  ASSERT_EQ(e.scene->lights().size(), 2000u);
  io::ImageMetrics m = fullCutsAgainstBrute(e, 96, 64);
  EXPECT_LE(m.fraction_over_threshold, 0.002) << "mean " << m.mean_relative_error << " p99 " << m.p99_relative_error;
}

// A patio under a pergola, as scripts/gen_pergola.py writes it: a lattice of thin beams
// and battens over a floor, two thirds of the lights high above it, the rest in four lamp
// clusters under it. Every cluster above is partly hidden from every point below, in a
// pattern that changes from light to light: one coin per cluster, tossed everywhere.
std::string pergola(uint32_t seed, int lights) {
  std::mt19937 rng(seed);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto g = [&](float m, float sd) { return std::normal_distribution<float>(m, sd)(rng); };
  const char* stone = "{ diffuse = (0.55, 0.5, 0.45); }";
  const char* wood = "{ diffuse = (0.45, 0.3, 0.2); specular = (0.2, 0.2, 0.2); shininess = 20; }";
  std::string t = "SBT-raytracer 1.0\ncamera { position = (-5.5, 2.4, 6.0); look_at = (1.0, 0.6, -1.0); fov = 60; }\n";
  t += box(0, -0.05f, 0, 14, 0.1f, 14, 0, stone) + box(0, 1.5f, -7, 14, 3, 0.2f, 0, stone) + box(7, 1.5f, 0, 0.2f, 3, 14, 0, stone);
  for (int i = -6; i <= 6; ++i) t += box(0.5f * float(i), 3, 0, 0.06f, 0.12f, 12, 0, wood);
  for (int k = -5; k <= 5; ++k) t += box(0, 3.15f, 1.1f * float(k), 12, 0.08f, 0.05f, 0, wood);
  for (float x : {-5.5f, 5.5f})
    for (float z : {-5.5f, 0.0f, 5.5f}) t += box(x, 1.5f, z, 0.2f, 3, 0.2f, 0, wood);
  for (int i = 0; i < 6; ++i) t += box(u(-4, 4), 0.4f, u(-4, 4), 1, 0.05f, 1, 0, wood);
  const float lamps[4][2] = {{-3, -3}, {3, -3}, {-3, 3}, {3, 3}};
  for (int i = 0; i < lights; ++i) {
    float x, y, z, r = 1, gr = 0.95f, b = 0.8f, k = 60.0f / float(lights);
    if (i % 3) {
      x = u(-8, 8), y = u(5, 9), z = u(-8, 8);
    } else {
      x = g(lamps[i % 4][0], 0.2f), y = g(2.5f, 0.1f), z = g(lamps[i % 4][1], 0.2f);
      gr = 0.7f, b = 0.4f, k *= 0.3f;
    }
    t += "point_light { position = (" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) +
         "); colour = (" + std::to_string(k * r) + "," + std::to_string(k * gr) + "," + std::to_string(k * b) + "); }\n";
  }
  return t;
}

// Under the lattice each cut node's error is its cluster's visible share sampled by one
// ray, the coin the criterion counts from the boundary rate (kHiddenSharePerBoundary,
// evaluator.cpp), and on the posts' faces beside the lights many clusters straddle the
// face's horizon (kExactSumMaxLights). Measured on this patio with full cuts: 3.7% of
// pixels over 2% with the earlier weight (4), 1.9% with the coin weighed at 2.576 standard
// deviations (a post's face +1.9% too bright), 0.5% with the straddling clusters' exact
// sums as well; and 0.22% with the hidden side of the coin counted too (hundreds of hidden
// representatives per point whose clusters are partly visible; 0.51% without it). Held to
// 0.4%, within the 99.5% that scenes nobody tuned to must reach.
TEST(Accuracy, LightcutsWithinTwoPercentUnderALattice) {
  io::ImageMetrics m = fullCutsAgainstBrute(Evaluated(pergola(4242, 6000)), 64, 64);
  EXPECT_LE(m.fraction_over_threshold, 0.004) << "mean " << m.mean_relative_error << " p99 " << m.p99_relative_error;
}

// A library as scripts/gen_library.py writes it: book stacks with slatted shelves, window
// panels (object lights) on the back wall, and point lights, a third in lamp clusters over
// the aisles and the rest 5 cm under the ceiling.
std::string library(uint32_t seed, int lights) {
  std::mt19937 rng(seed);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto g = [&](float m, float sd) { return std::normal_distribution<float>(m, sd)(rng); };
  const char* wall = "{ diffuse = (0.7, 0.68, 0.64); }";
  const char* oak = "{ diffuse = (0.45, 0.3, 0.18); }";
  std::string t = "SBT-raytracer 1.0\ncamera { position = (-3.6, 1.6, 4.2); look_at = (1.0, 1.1, -1.5); fov = 60; }\n";
  t += box(0, -0.05f, 0, 10, 0.1f, 10, 0, "{ diffuse = (0.4, 0.32, 0.25); }") + box(0, 3.05f, 0, 10, 0.1f, 10, 0, wall);
  t += box(-5, 1.5f, 0, 0.1f, 3, 10, 0, wall) + box(0, 1.5f, -5, 10, 3, 0.1f, 0, wall);
  for (int i = 0; i < 4; ++i)
    t += "translate(" + std::to_string(-3 + 2 * i) +
         ", 1.9, -4.94, scale(0.9, 1.2, 1, square { material = { diffuse = (0, 0, 0); "
         "luminosity = { colour = (0.8, 0.85, 1); intensity = 6; density = 40; }; }; }))\n";
  for (int r = 0; r < 4; ++r) {
    const float z = 1.5f - 1.4f * float(r);
    for (float xs : {-2.5f, 0.5f}) {
      t += box(xs - 1.2f, 1.1f, z, 0.04f, 2.2f, 0.4f, 0, oak) + box(xs + 1.2f, 1.1f, z, 0.04f, 2.2f, 0.4f, 0, oak);
      for (int h = 0; h < 5; ++h) {
        const float y = 0.1f + 0.5f * float(h);
        for (int sl = 0; sl < 3; ++sl) t += box(xs, y, z - 0.13f + 0.13f * float(sl), 2.4f, 0.025f, 0.08f, 0, oak);
        if (h < 4)
          for (int b = std::uniform_int_distribution<int>(6, 14)(rng); b > 0; --b)
            t += box(xs - 1.1f + u(0, 2.2f), y + 0.16f, z, 0.05f, 0.28f, 0.3f, 0, "{ diffuse = (0.5, 0.2, 0.15); }");
      }
    }
  }
  const float lampX[3] = {-1.0f, 2.2f, -4.0f};
  for (int k = 0; k < lights; ++k) {
    float x, y, z;
    if (k % 3 == 0) {
      const float zc = 2.2f - 1.4f * float(std::uniform_int_distribution<int>(0, 4)(rng));
      x = g(lampX[std::uniform_int_distribution<int>(0, 2)(rng)], 0.1f), y = g(2.6f, 0.05f), z = g(zc, 0.1f);
    } else {
      x = u(-4.8f, 4.8f), y = 2.95f, z = u(-4.8f, 4.8f);
    }
    const float c = 5.0f / float(lights);
    t += "point_light { position = (" + std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) +
         "); colour = (" + std::to_string(c) + "," + std::to_string(c * 0.95f) + "," + std::to_string(c * 0.85f) +
         "); }\n";
  }
  return t;
}

// Seen from the library's ceiling, hundreds of refinements of clear clusters (the lights
// just under it) and a few of the windows' small clusters, which a shelf's edge splits: the
// visibility coin's rate is counted over the refinements of clusters that are not clear
// (kHiddenSharePerBoundary, evaluator.cpp). Counted over all of them, the windows' clusters
// were priced near zero and 2.0% of the pixels were over 2% (0.37% with the rate over
// clusters that are not clear, 0.33% with second samples too: kSecondSampleShare).
TEST(Accuracy, LightcutsWithinTwoPercentOnALibrarysCeiling) {
  io::ImageMetrics m = fullCutsAgainstBrute(Evaluated(library(77, 2000)), 64, 42);
  EXPECT_LE(m.fraction_over_threshold, 0.005) << "mean " << m.mean_relative_error << " p99 " << m.p99_relative_error;
}

// Clusters proven clear (Visibility::boxClear) are refined without rays. With a zero
// threshold every cluster is refined down to its lights, so the image must be brute
// force's: any cluster wrongly called clear would show there as light through a wall.
// At the default threshold they save rays at the same accuracy.
TEST(Accuracy, ClearClustersAreExactAndSaveShadowRays) {
  auto s = scene::Scene::build(io::parseRayString(randomRoom(778, 1500), "room.ray", "."));
  auto brute = lightcuts::makeBruteForce(s->lights());
  lightcuts::LightForest forest = lightcuts::buildLightForest(s->lights());
  lightcuts::CutOptions exact;
  exact.errorRatio = 0;
  exact.maxCut = 1 << 20;
  auto lcExact = lightcuts::makeLightcuts(s->lights(), forest, exact);
  RenderResult ref = renderWith(*s, *brute, 24);
  RenderResult test = renderWith(*s, *lcExact, 24);
  EXPECT_GT(test.stats.eval.clearedClusters, 100u);
  for (size_t i = 0; i < ref.image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(test.image.pixels[i][c], ref.image.pixels[i][c], 1e-4f * (ref.image.pixels[i][c] + 1e-3f)) << i;

  lightcuts::CutOptions off;
  off.clearClusters = false;
  auto lcOn = lightcuts::makeLightcuts(s->lights(), forest, lightcuts::CutOptions{});
  auto lcOff = lightcuts::makeLightcuts(s->lights(), forest, off);
  RenderResult big = renderWith(*s, *brute, 48);
  RenderResult on = renderWith(*s, *lcOn, 48), without = renderWith(*s, *lcOff, 48);
  EXPECT_EQ(without.stats.eval.clearTests, 0u);
  EXPECT_LT(double(on.stats.eval.shadowRays), 0.8 * double(without.stats.eval.shadowRays));
  EXPECT_LE(io::compareImages(big.image, on.image).fraction_over_threshold, 0.002);
}

TEST(Accuracy, LightcutsWithinTwoPercentOfBruteForceOnTheCornellBox) {
  Loaded l = loadCornell();
  const scene::Scene& s = *l.scene;
  ASSERT_GT(s.lights().size(), 8000u);
  const int W = 40;
  auto brute = lightcuts::makeBruteForce(s.lights());
  lightcuts::LightForest forest = lightcuts::buildLightForest(s.lights());
  auto lc = lightcuts::makeLightcuts(s.lights(), forest, lightcuts::CutOptions{});
  RenderResult ref = renderWith(s, *brute, W);
  RenderResult test = renderWith(s, *lc, W);
  io::ImageMetrics m = io::compareImages(ref.image, test.image);
  EXPECT_LE(m.fraction_over_threshold, 0.01) << "mean " << m.mean_relative_error << " p99 " << m.p99_relative_error;
  // And it did so with far fewer lights than brute force.
  double cut = double(test.stats.eval.cutNodes) / double(test.stats.eval.shadingPoints);
  EXPECT_LT(cut, 0.1 * double(s.lights().size()));
  // Walter's per-node rule alone is cheaper and less accurate: the reason for the default.
  auto walter = lightcuts::makeLightcuts(s.lights(), forest,
                                         lightcuts::CutOptions{0.02f, 1000, lightcuts::CutCriterion::Walter});
  RenderResult w = renderWith(s, *walter, W);
  EXPECT_LT(w.stats.eval.cutNodes, test.stats.eval.cutNodes);
  EXPECT_GT(io::compareImages(ref.image, w.image).mean_relative_error, m.mean_relative_error);
}

// With a zero threshold a lightcut refines every cluster it cannot prove hidden down to
// its lights, so it must give brute force's image: the clusters the visibility probes
// proved hidden behind the boxes (convex meshes) were hidden.
TEST(Accuracy, ZeroThresholdCutsEqualBruteForceWithHiddenClusters) {
  Loaded l = loadCornell();
  const scene::Scene& s = *l.scene;
  auto brute = lightcuts::makeBruteForce(s.lights());
  lightcuts::LightForest forest = lightcuts::buildLightForest(s.lights());
  lightcuts::CutOptions o;
  o.errorRatio = 0;
  o.maxCut = 1 << 20;
  auto lc = lightcuts::makeLightcuts(s.lights(), forest, o);
  RenderResult ref = renderWith(s, *brute, 24);
  RenderResult test = renderWith(s, *lc, 24);
  EXPECT_GT(test.stats.eval.hiddenClusters, 0u);
  for (size_t i = 0; i < ref.image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(test.image.pixels[i][c], ref.image.pixels[i][c], 1e-4f * (ref.image.pixels[i][c] + 1e-3f)) << i;
}

TEST(Accuracy, ReconstructionCutsWithinTwoPercentWithFarFewerShadowRays) {
  Loaded l = loadCornell();
  const scene::Scene& s = *l.scene;
  const int W = 64;
  auto brute = lightcuts::makeBruteForce(s.lights());
  lightcuts::LightForest forest = lightcuts::buildLightForest(s.lights());
  auto lc = lightcuts::makeLightcuts(s.lights(), forest, lightcuts::CutOptions{});
  RenderResult ref = renderWith(s, *brute, W);
  RenderResult full = renderWith(s, *lc, W);
  RenderResult rec = renderWith(s, *lc, W, 4);
  io::ImageMetrics m = io::compareImages(ref.image, rec.image);
  EXPECT_LE(m.fraction_over_threshold, 0.01) << "mean " << m.mean_relative_error << " p99 " << m.p99_relative_error;
  EXPECT_GT(rec.stats.reconstructionSamples, 0u);
  EXPECT_GT(rec.stats.eval.reconstructedPoints, rec.stats.eval.shadingPoints / 2);
  // Most points borrow visibility: fewer shadow rays than a lightcut at every point (in
  // an image this small, edges, where points need their own cuts, are a large share; the
  // ratio is 0.81 here, and about a fifth at 512 x 512, docs/BENCHMARKS.md). It was 0.70
  // while the full cuts' probes of the blocks, convex meshes, still cost corner rays.
  EXPECT_LT(double(rec.stats.eval.shadowRays), 0.85 * double(full.stats.eval.shadowRays));
  for (uint8_t d : rec.done) ASSERT_EQ(d, 1);
  EXPECT_EQ(rec.stats.reconstructionCoarseCells, 0u);

  // Coarse cells of 8 where their corners agree: fewer samples, the same accuracy.
  RenderResult coarse = renderWith(s, *lc, W, 4, 8);
  io::ImageMetrics mc = io::compareImages(ref.image, coarse.image);
  EXPECT_LE(mc.fraction_over_threshold, 0.01) << "mean " << mc.mean_relative_error << " p99 " << mc.p99_relative_error;
  EXPECT_GT(coarse.stats.reconstructionCoarseCells, 0u);
  EXPECT_LT(coarse.stats.reconstructionSamples, rec.stats.reconstructionSamples);
  for (uint8_t d : coarse.done) ASSERT_EQ(d, 1);
}

// A floor seen from above under a row of thin slats, lit by lights scattered above them:
// each light lays a slat's shadow, narrower than a pixel, somewhere else on the floor, so
// the floor is striped with shadows that fall between samples four pixels apart. There
// the samples disagree about much of their light, and a cell that splits where they do
// (RenderOptions::reconstructSplit) finds the stripes all four of its corners stepped over.
std::string slatFloor(uint32_t seed, int lights) {
  std::mt19937 rng(seed);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  std::string t = "SBT-raytracer 1.0\ncamera { position = (0, 3, 0.01); look_at = (0, 0, 0); fov = 45; }\n";
  t += box(0, -0.05f, 0, 4, 0.1f, 4, 0, "{ diffuse = (0.6, 0.6, 0.6); }");
  for (int k = 0; k < 9; ++k) t += box(-1.2f + 0.3f * float(k), 0.25f, 0, 0.03f, 0.03f, 3, 0, "{ diffuse = (0.3, 0.3, 0.3); }");
  for (int i = 0; i < lights; ++i)
    t += "point_light { position = (" + std::to_string(u(-2, 2)) + "," + std::to_string(u(0.8f, 1.6f)) + "," +
         std::to_string(u(-2, 2)) + "); colour = (" + std::to_string(2.0f / float(lights)) + "," +
         std::to_string(2.0f / float(lights)) + "," + std::to_string(2.0f / float(lights)) + "); }\n";
  return t;
}

// The striped floor's options: pixel centres, 64 x 64, samples every 4 pixels.
RenderOptions slatFloorOptions() {
  RenderOptions o;
  o.aa = AntiAliasing::Off;
  o.width = o.height = 64;
  o.reconstructSpacing = 4;
  return o;
}

TEST(Accuracy, CellsSplitWhereTheirSamplesDisagreeCatchShadowsBetweenThem) {
  Evaluated e(slatFloor(5, 400));
  RenderOptions o = slatFloorOptions();
  o.reconstructRefine = false;  // the disagreement alone
  RenderResult ref = render(*e.scene, *e.brute, o);
  o.reconstructSplit = 1;  // never split: the stripes between samples are missed
  RenderResult whole = render(*e.scene, *e.lc, o);
  o.reconstructSplit = RenderOptions{}.reconstructSplit;
  RenderResult split = render(*e.scene, *e.lc, o);
  const io::ImageMetrics mw = io::compareImages(ref.image, whole.image), ms = io::compareImages(ref.image, split.image);
  EXPECT_EQ(whole.stats.reconstructionSplitCells, 0u);
  EXPECT_GT(split.stats.reconstructionSplitCells, 0u);
  EXPECT_GT(split.stats.reconstructionSamples, whole.stats.reconstructionSamples);
  EXPECT_GT(mw.fraction_over_threshold, 0.02) << "mean " << mw.mean_relative_error;
  EXPECT_LE(ms.fraction_over_threshold, 0.01) << "mean " << ms.mean_relative_error << " p99 " << ms.p99_relative_error;
  for (uint8_t d : split.done) ASSERT_EQ(d, 1);
}

// The same striped floor with cells that never split for disagreeing: there a point's group
// probe finds a shadow its corners stepped over, and with RenderOptions::reconstructRefine
// its cell splits (new samples nearer its pixels) where without it only that point
// re-traces the group and its neighbours keep the corners' wrong visibility.
TEST(Accuracy, CellsRefineWhereAProbeRefutesTheirSamples) {
  Evaluated e(slatFloor(5, 400));
  RenderOptions o = slatFloorOptions();
  o.reconstructSplit = 1;
  RenderResult ref = render(*e.scene, *e.brute, o);
  o.reconstructRefine = false;
  RenderResult off = render(*e.scene, *e.lc, o);
  o.reconstructRefine = true;
  RenderResult on = render(*e.scene, *e.lc, o);
  const io::ImageMetrics moff = io::compareImages(ref.image, off.image), mon = io::compareImages(ref.image, on.image);
  EXPECT_EQ(off.stats.reconstructionRefinedCells, 0u);
  EXPECT_GT(off.stats.eval.refutingGroupProbes, 0u);
  EXPECT_GT(on.stats.reconstructionRefinedCells, 0u);
  EXPECT_GT(on.stats.reconstructionSamples, off.stats.reconstructionSamples);
  EXPECT_LT(mon.fraction_over_threshold, 0.7 * moff.fraction_over_threshold)
      << "off " << moff.fraction_over_threshold << " on " << mon.fraction_over_threshold;
  for (uint8_t d : on.done) ASSERT_EQ(d, 1);
}

// The striped floor antialiased, with cells that never split for disagreeing: under
// RenderOptions::reconstructRefine a sub-sample whose probe refutes its samples takes a
// full cut (a sample for the rest of its pixel), as well as the cells splitting.
TEST(Accuracy, SubSamplesTakeFullCutsWhereAProbeRefutesTheirSamples) {
  Evaluated e(slatFloor(5, 400));
  RenderOptions o = slatFloorOptions();
  o.aa = AntiAliasing::Adaptive;
  o.reconstructSplit = 1;
  o.referencePixels = 4096;
  o.reconstructRefine = false;
  RenderResult off = render(*e.scene, *e.lc, o);
  o.reconstructRefine = true;
  RenderResult on = render(*e.scene, *e.lc, o);
  EXPECT_GT(on.stats.aaPixels, 0u);
  EXPECT_GT(on.stats.reconstructionFallbacks, off.stats.reconstructionFallbacks);
  const ReferenceStats &a = off.stats.reference, &b = on.stats.reference;
  // Measured (with the cells' refinement): 64% -> 32% of pixels over 2%, mean error 5.4% ->
  // 2.2%; full cuts at sub-samples 730 -> 830.
  EXPECT_LT(b.fractionOver2pct, 0.7 * a.fractionOver2pct);
  EXPECT_LT(b.meanRelativeError, 0.7 * a.meanRelativeError);
}

// A fence of `boards` upright boards (thickness x height x 3), `pitch` apart and centred,
// standing on a floor seen from above, lit by 300 low point lights on both sides.
std::string fenceScene(int boards, float pitch, float thickness, float height) {
  std::mt19937 rng(11);
  auto u = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  std::string t = "SBT-raytracer 1.0\ncamera { position = (0, 3, 0.01); look_at = (0, 0, 0); fov = 45; }\n";
  t += box(0, -0.05f, 0, 4, 0.1f, 4, 0, "{ diffuse = (0.6, 0.6, 0.6); }");
  for (int k = 0; k < boards; ++k)
    t += box(pitch * (float(k) - 0.5f * float(boards - 1)), 0.5f * height, 0, thickness, height, 3, 0,
             "{ diffuse = (0.3, 0.3, 0.3); }");
  for (int i = 0; i < 300; ++i)
    t += "point_light { position = (" + std::to_string(u(-2, 2)) + "," + std::to_string(u(0.1f, 0.6f)) + "," +
         std::to_string(u(-1.5f, 1.5f)) + "); colour = (0.01, 0.01, 0.01); }\n";
  return t;
}

// A floor seen from above, crossed by a fence of upright boards standing on it, lit by
// lights low on both sides: each board's two sides of the floor see different lights, so
// an antialiasing sub-sample beside a board must not borrow from a sample across it
// (RenderOptions::aaSeparationTest).
TEST(Accuracy, SubSamplesCutOffFromTheirSamplesTakeFullCuts) {
  Evaluated e(fenceScene(7, 0.3f, 0.03f, 0.4f));
  const scene::Scene* s = e.scene.get();
  const lightcuts::LightEvaluator* lc = e.lc.get();
  RenderOptions o;
  o.width = o.height = 256;
  o.reconstructSpacing = 4;
  o.referencePixels = 4096;
  o.aaSeparationTest = false;
  RenderResult off = render(*s, *lc, o);
  o.aaSeparationTest = true;
  RenderResult on = render(*s, *lc, o);
  EXPECT_GT(on.stats.aaPixels, 0u);
  EXPECT_GT(on.stats.reconstructionFallbacks, off.stats.reconstructionFallbacks);
  // Measured: 3.27% -> 3.22% of reference pixels over 2% (the rest is the boards' faces,
  // seen edge on, docs/LIGHTCUTS.md); on a pierced screen at 512 x 512, 0.98% -> 0.68%.
  EXPECT_LE(on.stats.reference.fractionOver2pct, off.stats.reference.fractionOver2pct);
  EXPECT_LT(on.stats.reference.meanRelativeError, off.stats.reference.meanRelativeError);
}

// A fence of thin boards 0.06 apart, seen from above (scripts/gen_fence.py), at 256 x 256
// under reconstruction cuts, with one of antialiasing's switches off, then on.
std::pair<RenderResult, RenderResult> fenceOffOn(bool RenderOptions::*option) {
  Evaluated e(fenceScene(25, 0.06f, 0.012f, 0.2f));
  RenderOptions o;
  o.width = o.height = 256;
  o.reconstructSpacing = 4;
  o.referencePixels = 4096;
  o.*option = false;
  RenderResult off = render(*e.scene, *e.lc, o);
  o.*option = true;
  RenderResult on = render(*e.scene, *e.lc, o);
  return {std::move(off), std::move(on)};
}

// On the fence a board's side face is seen nearly edge on, so a pixel's sub-samples hit it
// at heights its samples (the pixel centres, all at one height) never saw, beyond their
// hull, where the next board hides other lights. With the probe for a surface near such a
// sub-sample (RenderOptions::aaExtrapolationProbe) they take full cuts.
TEST(Accuracy, SubSamplesBeyondTheirSamplesNearASurfaceTakeFullCuts) {
  const auto [off, on] = fenceOffOn(&RenderOptions::aaExtrapolationProbe);
  EXPECT_GT(on.stats.reconstructionFallbacks, off.stats.reconstructionFallbacks);
  EXPECT_GT(on.stats.eval.shadowRays, off.stats.eval.shadowRays);
  // Measured at 256 x 256: 14.8% -> 0.46% of reference pixels over 2%, worst pixel 72% ->
  // 8.6% (1.9% and 12% before pixel samples and the quarter-footprint gate; at 512 x 512,
  // as the 25-board fence of gen_fence.py: 7.4% -> 0.7%).
  const ReferenceStats &a = off.stats.reference, &b = on.stats.reference;
  EXPECT_GT(a.fractionOver2pct, 0.05);
  EXPECT_LT(b.fractionOver2pct * 4, a.fractionOver2pct);
  EXPECT_LT(b.maxRelativeError * 2, a.maxRelativeError);
}

// Spacing 1 (--reconstruct 1): the pixel centres take full cuts (recorded ones, refined as
// a sample's are) and antialiasing's sub-samples are rebuilt from them. In a room of boxes
// the flagged pixels stay within 2% of brute force at their own sub-samples (the reference
// pixels), for far fewer shadow rays than a full cut at every sub-sample. (On fine geometry
// it loses accuracy, which is why it is not the default: docs/LIGHTCUTS.md.)
TEST(Accuracy, SubSamplesRebuiltFromPixelCentresStayWithinTwoPercent) {
  Evaluated e(randomRoom(5, 2000));
  RenderOptions o;
  o.width = 96;
  o.height = 64;
  o.referencePixels = 1024;
  RenderResult full = render(*e.scene, *e.lc, o);
  o.reconstructSpacing = 1;
  RenderResult rebuilt = render(*e.scene, *e.lc, o);
  EXPECT_GT(rebuilt.stats.aaPixels, 100u);
  EXPECT_GT(rebuilt.stats.eval.reconstructedPoints, rebuilt.stats.aaPixels * 4);
  // Measured: 1,161 flagged pixels, 11,802 points rebuilt; shadow rays 5.34M -> 2.35M,
  // reference pixels over 2% 0% -> 0%, p99 0.95% -> 0.97%, worst 1.29% -> 1.30%.
  EXPECT_LT(rebuilt.stats.eval.shadowRays * 100, full.stats.eval.shadowRays * 60);
  const ReferenceStats &a = full.stats.reference, &b = rebuilt.stats.reference;
  EXPECT_LT(b.fractionOver2pct, 0.01) << "p99 " << b.p99RelativeError << " max " << b.maxRelativeError;
  EXPECT_LT(b.p99RelativeError, a.p99RelativeError * 1.5 + 0.002);
}

// The same fence: sub-samples beyond their samples along a board's side face take full
// cuts, a few in each such pixel. With each full cut a sample for the sub-samples after it
// in its pixel and the next pixels (RenderOptions::aaPixelSamples), they borrow from it:
// about half the full cuts, far fewer shadow rays, and the error still within 2% on 99% of
// pixels.
TEST(Accuracy, SubSamplesFullCutsServeTheRestOfTheirPixel) {
  const auto [own, shared] = fenceOffOn(&RenderOptions::aaPixelSamples);
  // Measured: full cuts 232,219 -> 107,833, shadow rays -25%, reference pixels over 2%
  // 0.39% -> 0.46%, the worst pixel 3.8% -> 8.6%. Since probes against boxes are decided
  // without rays the full cuts it saves are cheaper: shadow rays 34.7M -> 28.3M (-19%).
  EXPECT_LT(shared.stats.reconstructionFallbacks * 2, own.stats.reconstructionFallbacks);
  EXPECT_LT(shared.stats.eval.shadowRays * 100, own.stats.eval.shadowRays * 88);
  EXPECT_LT(shared.stats.reference.fractionOver2pct, 0.01);
  EXPECT_LT(shared.stats.reference.fractionOver2pct, own.stats.reference.fractionOver2pct + 0.002);
  EXPECT_LT(shared.stats.reference.maxRelativeError, 0.1);
}

}  // namespace
}  // namespace lc::render

namespace lc::render {
namespace {

TEST(Determinism, ReconstructionCutsImageIsTheSameAtOneAndTwoThreads) {
  Loaded l = loadCornell();
  lightcuts::LightForest forest = lightcuts::buildLightForest(l.scene->lights());
  auto lc = lightcuts::makeLightcuts(l.scene->lights(), forest, lightcuts::CutOptions{});
  // (spacing, coarse cells); spacing 1: a full cut at every pixel centre, the other
  // points rebuilt from them.
  const std::pair<int, int> grids[] = {{4, 0}, {4, 8}, {1, 0}};
  for (int spp : {1, 2})
    for (const auto& [spacing, coarse] : grids) {
      RenderOptions o;
      o.width = 70;  // not a multiple of the spacing or the tile: partial cells and tiles
      o.height = 45;
      o.spp = spp;
      o.reconstructSpacing = spacing;
      o.reconstructCoarseSpacing = coarse;
      o.threads = 1;
      RenderResult a = render(*l.scene, *lc, o);
      o.threads = 2;
      RenderResult b = render(*l.scene, *lc, o);
      for (size_t i = 0; i < a.image.pixels.size(); ++i)
        ASSERT_EQ(a.image.pixels[i], b.image.pixels[i]) << spp << " " << spacing << " " << coarse << " " << i;
      for (uint8_t d : a.done) ASSERT_EQ(d, 1);
      EXPECT_EQ(a.stats.reconstructionCoarseCells, b.stats.reconstructionCoarseCells);
    }
}

TEST(Determinism, LightcutsImageIsTheSameAtOneAndTwoThreads) {
  Loaded l = loadCornell();
  lightcuts::LightForest forest = lightcuts::buildLightForest(l.scene->lights());
  auto lc = lightcuts::makeLightcuts(l.scene->lights(), forest, lightcuts::CutOptions{});
  RenderOptions o;
  o.width = o.height = 24;
  o.spp = 2;
  o.threads = 1;
  RenderResult a = render(*l.scene, *lc, o);
  o.threads = 2;
  RenderResult b = render(*l.scene, *lc, o);
  for (size_t i = 0; i < a.image.pixels.size(); ++i) ASSERT_EQ(a.image.pixels[i], b.image.pixels[i]) << i;
  // The tree (and its representatives) is the same when built again.
  lightcuts::LightForest again = lightcuts::buildLightForest(l.scene->lights());
  ASSERT_EQ(again.nodeCount(), forest.nodeCount());
  for (size_t t = 0; t < forest.trees.size(); ++t)
    for (size_t i = 0; i < forest.trees[t].nodes.size(); ++i) {
      ASSERT_EQ(forest.trees[t].nodes[i].rep, again.trees[t].nodes[i].rep);
      ASSERT_EQ(forest.trees[t].nodes[i].a, again.trees[t].nodes[i].a);
      ASSERT_EQ(forest.trees[t].nodes[i].b, again.trees[t].nodes[i].b);
    }
}

}  // namespace
}  // namespace lc::render
