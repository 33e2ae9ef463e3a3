// End to end: Lightcuts against brute force on the default scene (object-light panel plus
// instant radiosity), the acceptance criterion of the product at a size a test can afford.
#include <gtest/gtest.h>

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

RenderResult renderWith(const scene::Scene& s, const lightcuts::LightEvaluator& ev, int w, int reconstruct = 0,
                        int coarse = 0) {
  RenderOptions o;
  o.aa = AntiAliasing::Off;  // checked at pixel centres (closed forms, per-pixel comparisons)
  o.width = o.height = w;
  o.reconstructSpacing = reconstruct;
  o.reconstructCoarseSpacing = coarse;
  return render(s, ev, o);
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
  // an image this small, edges, where points need their own cuts, are a large share).
  EXPECT_LT(double(rec.stats.eval.shadowRays), 0.7 * double(full.stats.eval.shadowRays));
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

}  // namespace
}  // namespace lc::render

namespace lc::render {
namespace {

TEST(Determinism, ReconstructionCutsImageIsTheSameAtOneAndTwoThreads) {
  Loaded l = loadCornell();
  lightcuts::LightForest forest = lightcuts::buildLightForest(l.scene->lights());
  auto lc = lightcuts::makeLightcuts(l.scene->lights(), forest, lightcuts::CutOptions{});
  for (int spp : {1, 2})
    for (int coarse : {0, 8}) {
      RenderOptions o;
      o.width = 70;  // not a multiple of the spacing or the tile: partial cells and tiles
      o.height = 45;
      o.spp = spp;
      o.reconstructSpacing = 4;
      o.reconstructCoarseSpacing = coarse;
      o.threads = 1;
      RenderResult a = render(*l.scene, *lc, o);
      o.threads = 2;
      RenderResult b = render(*l.scene, *lc, o);
      for (size_t i = 0; i < a.image.pixels.size(); ++i)
        ASSERT_EQ(a.image.pixels[i], b.image.pixels[i]) << spp << " " << coarse << " " << i;
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
