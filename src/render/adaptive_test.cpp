// Adaptive antialiasing: which pixels are flagged, where sub-samples go, an edge's pixels
// coming out as the area each side covers, and the reference pixels evaluating the same
// sub-samples.
#include "render/adaptive.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "io/image.h"
#include "io/ray_parser.h"
#include "lightcuts/light_tree.h"
#include "test_util.h"

namespace lc::render {
namespace {

std::unique_ptr<scene::Scene> sceneFrom(const std::string& text) {
  io::SceneDesc d = io::parseRayString(text, "test.ray", "");
  return scene::Scene::build(d);
}

CentreSample hitOn(int shape, Vec3 n, float lum) {
  CentreSample c;
  c.shape = shape;
  c.n = n;
  c.luminance = lum;
  c.known = true;
  return c;
}

TEST(AdaptiveFlags, ShapeNormalAndContrastEachFlagBothSides) {
  RenderOptions o;
  const Vec3 z(0, 0, 1);
  EXPECT_FALSE(disagree(hitOn(1, z, 0.5f), hitOn(1, z, 0.52f), o));  // 4%: noise, not an edge
  EXPECT_TRUE(disagree(hitOn(1, z, 0.5f), hitOn(2, z, 0.5f), o));    // another shape
  EXPECT_TRUE(disagree(hitOn(1, z, 0.5f), CentreSample{}, o));       // the background
  EXPECT_TRUE(disagree(hitOn(1, z, 0.5f), hitOn(1, normalize(Vec3(0, 1, 1)), 0.5f), o));  // 45 degrees
  EXPECT_FALSE(disagree(hitOn(1, z, 0.5f), hitOn(1, normalize(Vec3(0, 0.2f, 1)), 0.5f), o));  // 11 degrees
  EXPECT_TRUE(disagree(hitOn(1, z, 0.5f), hitOn(1, z, 0.3f), o));   // 40% contrast: a shadow edge
  EXPECT_FALSE(disagree(hitOn(1, z, 0.5f), hitOn(1, z, 0.4f), o));  // 20%: below aaContrast (25%)
  EXPECT_TRUE(disagree(hitOn(1, z, 2.0f), hitOn(1, z, 0.7f), o));   // compared as displayed: 1 vs 0.7
  EXPECT_FALSE(disagree(hitOn(1, z, 5.0f), hitOn(1, z, 3.0f), o));  // both white on screen
  EXPECT_FALSE(disagree(hitOn(1, z, 0.001f), hitOn(1, z, 0.002f), o));  // below the floor
  CentreSample unknown = hitOn(1, z, 0.0f);
  unknown.known = false;  // across a tile border: luminance not compared here (seamPixels)
  EXPECT_FALSE(disagree(hitOn(1, z, 0.5f), unknown, o));
  CentreSample outside;
  outside.shape = -2;
  EXPECT_FALSE(disagree(hitOn(1, z, 0.5f), outside, o));

  // A 4 x 3 tile (6 x 5 with its ring) with a vertical edge between columns 1 and 2.
  const int w = 4, h = 3;
  std::vector<CentreSample> ring(size_t(w + 2) * size_t(h + 2));
  for (int y = 0; y < h + 2; ++y)
    for (int x = 0; x < w + 2; ++x) ring[size_t(y) * (w + 2) + x] = hitOn(x < 3 ? 1 : 2, z, 0.5f);
  std::vector<uint8_t> f = flagPixels(ring, w, h, o);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_EQ(f[size_t(y) * w + x], x == 1 || x == 2) << x << "," << y;
}

// A bend of more than aaStep along three centres flags the middle one: a step of lower
// contrast than aaContrast does, a straight ramp (however steep) does not.
TEST(AdaptiveFlags, StepsFlagABendNotAStraightRamp) {
  RenderOptions o;
  const Vec3 z(0, 0, 1);
  auto at = [&](float l) { return hitOn(1, z, l); };
  EXPECT_FALSE(steps(at(0.3f), at(0.4f), at(0.5f), o));    // a ramp: no bend
  EXPECT_TRUE(steps(at(0.5f), at(0.5f), at(0.44f), o));    // a 12% step: disagree() misses it
  EXPECT_FALSE(disagree(at(0.5f), at(0.44f), o));
  EXPECT_FALSE(steps(at(0.5f), at(0.5f), at(0.48f), o));   // 4%: noise
  EXPECT_TRUE(steps(at(0.5f), at(0.56f), at(0.5f), o));    // a thin bright line
  EXPECT_FALSE(steps(at(3.0f), at(1.5f), at(1.2f), o));    // white on screen
  CentreSample unknown = at(0.0f);
  unknown.known = false;
  EXPECT_FALSE(steps(at(0.5f), at(0.5f), unknown, o));
  o.aaStep = 0;  // off
  EXPECT_FALSE(steps(at(0.5f), at(0.5f), at(0.2f), o));

  // A 6 x 3 tile: a ramp of 12-15% per column, then the same with a 12% step in it.
  RenderOptions d;
  const int w = 6, h = 3;
  std::vector<CentreSample> ring(size_t(w + 2) * size_t(h + 2));
  auto fill = [&](auto lum) {
    for (int y = 0; y < h + 2; ++y)
      for (int x = 0; x < w + 2; ++x) {
        CentreSample c = at(lum(x));
        c.known = x >= 1 && x <= w && y >= 1 && y <= h;
        ring[size_t(y) * (w + 2) + x] = c;
      }
  };
  fill([](int x) { return 0.40f + 0.06f * float(x); });
  std::vector<uint8_t> f = flagPixels(ring, w, h, d);
  EXPECT_EQ(std::count(f.begin(), f.end(), 1), 0);
  fill([](int x) { return x < 4 ? 0.5f : 0.44f; });  // the step between tile columns 2 and 3
  f = flagPixels(ring, w, h, d);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_EQ(f[size_t(y) * w + x], x == 2 || x == 3) << x << "," << y;
}

// The seams: a pixel on a tile border is compared with its neighbours across it after every
// tile is done; pixels inside tiles, and those flagged already, are not listed.
TEST(AdaptiveSeams, BordersAreComparedAcrossTiles) {
  RenderOptions o;
  o.width = 8;
  o.height = 4;
  RenderResult res;
  res.image = io::Image(8, 4);
  res.aaFlagged.assign(32, 0);
  res.centreLuminance.assign(32, 0.0f);
  auto setColumns = [&](auto lum) {
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 8; ++x) res.centreLuminance[size_t(y) * 8 + size_t(x)] = lum(x);
  };
  // A 20% step between columns 3 and 4, on the border of 4-pixel tiles: under aaContrast,
  // over aaStep.
  setColumns([](int x) { return x < 4 ? 0.5f : 0.4f; });
  std::vector<std::pair<int, int>> s = seamPixels(res, o, 4);
  ASSERT_EQ(s.size(), 8u);
  for (auto [x, y] : s) EXPECT_TRUE(x == 3 || x == 4) << x << "," << y;
  EXPECT_EQ(s.front(), std::make_pair(3, 0));  // row order
  // With tiles of 8 the step is inside a tile: adaptiveTile's, not a seam.
  EXPECT_TRUE(seamPixels(res, o, 8).empty());
  // Pixels flagged already are not listed again.
  for (int y = 0; y < 4; ++y) res.aaFlagged[size_t(y) * 8 + 3] = 1;
  s = seamPixels(res, o, 4);
  ASSERT_EQ(s.size(), 4u);
  for (auto [x, y] : s) EXPECT_EQ(x, 4);
  // A smooth ramp across the border is not a seam; nor anything with antialiasing off.
  res.aaFlagged.assign(32, 0);
  setColumns([](int x) { return 0.3f + 0.05f * float(x); });
  EXPECT_TRUE(seamPixels(res, o, 4).empty());
  setColumns([](int x) { return x < 4 ? 0.5f : 0.4f; });
  o.aa = AntiAliasing::Off;
  EXPECT_TRUE(seamPixels(res, o, 4).empty());
}

TEST(AdaptiveSubSamples, OneInEachStratumButTheMiddle) {
  std::vector<Vec2> p;
  for (int n : {8, 24, 48, 80}) {
    const int g = aaGridSide(n);
    ASSERT_EQ(g * g - 1, n);
    Rng rng(1, 7);
    aaSubSamplePositions(g, rng, p);
    ASSERT_EQ(int(p.size()), n);
    std::set<int> strata, columns, rows;
    for (const Vec2& u : p) {
      ASSERT_TRUE(u.x >= 0 && u.x < 1 && u.y >= 0 && u.y < 1);
      strata.insert(int(u.y * float(g)) * g + int(u.x * float(g)));
      columns.insert(int(u.x * float(g * g)));
      rows.insert(int(u.y * float(g * g)));
    }
    EXPECT_EQ(int(strata.size()), n);
    EXPECT_EQ(strata.count(g * g / 2), 0u);
    // One per thin column and row but the centre's (multi-jittered).
    EXPECT_EQ(int(columns.size()), n);
    EXPECT_EQ(columns.count(g * g / 2), 0u);
    EXPECT_EQ(int(rows.size()), n);
    EXPECT_EQ(rows.count(g * g / 2), 0u);
  }
  EXPECT_EQ(aaGridSide(16), 0);
  EXPECT_EQ(antiAliasingName(parseAntiAliasing("off")), std::string("off"));
  EXPECT_EQ(parseAntiAliasing("adaptive"), AntiAliasing::Adaptive);
  EXPECT_THROW(parseAntiAliasing("fxaa"), Error);
  EXPECT_EQ(RenderOptions{}.aa, AntiAliasing::Adaptive);  // the default
}

// An emissive half-plane x < 0.2 seen head on, black beyond: a pixel's value is the share of
// its area left of the edge.
const char* kEdgeScene = R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 90; }
trimesh { points = ((-20, -20, 0), (0.2, -20, 0), (0.2, 20, 0), (-20, 20, 0)); faces = ((0, 1, 2), (0, 2, 3));
  material = { emissive = (1, 1, 1); }; }
)";

// Decoupled shading (RenderOptions::aaDecoupled): a lit diffuse floor's silhouette against
// the sky keeps its coverage while sub-samples take a shaded neighbour's radiance; the image
// stays within 2% of shading every sub-sample (hard shadows and highlights, whose surfaces'
// shaded samples disagree, are shaded in full), with fewer shadow rays.
TEST(AdaptiveRender, DecoupledShadingKeepsCoverageAtAFractionOfTheShading) {
  const char* scene = R"(SBT-raytracer 1.0
camera { position = (0, 1, 5); viewdir = (0, -0.1, -1); updir = (0, 1, 0); fov = 60; }
point_light { position = (0.5, 3, 1); colour = (3, 3, 3); }
point_light { position = (-1, 2, 2); colour = (2, 2, 2); }
sphere { material = { diffuse = (0.7, 0.5, 0.3); specular = (0.2, 0.2, 0.2); shininess = 20; }; }
translate(0, -1, 0, scale(6, 0.1, 6, box { material = { diffuse = (0.6, 0.6, 0.6); }; }))
)";
  auto s = sceneFrom(scene);
  auto ev = lightcuts::makeBruteForce(s->lights());
  RenderOptions o;
  o.width = o.height = 48;
  o.aaSamples = 48;
  RenderOptions full = o;
  full.aaDecoupled = false;
  RenderResult a = render(*s, *ev, o), b = render(*s, *ev, full);
  ASSERT_GT(a.stats.aaPixels, 20u);
  EXPECT_EQ(a.stats.aaPixels, b.stats.aaPixels);
  EXPECT_EQ(a.stats.primaryRays, b.stats.primaryRays);
  int over = 0;
  for (size_t i = 0; i < a.image.pixels.size(); ++i) {
    const float la = luminance(a.image.pixels[i]), lb = luminance(b.image.pixels[i]);
    over += std::fabs(la - lb) > 0.02f * std::max(lb, 0.05f);
  }
  EXPECT_LE(over, int(a.image.pixels.size() / 100)) << "pixels over 2% of full shading";
  EXPECT_LT(a.stats.eval.shadowRays, b.stats.eval.shadowRays);
}

// A floor with a diffuse checker texture: its sub-samples share shading like a plain
// surface's (one per cell of the 3 x 3 grid), each scaled by its own texel, and the image
// matches shading every sub-sample within 2%; the same floor with a specular term keeps the fine
// grid's 49 shadings (the ratio would scale its highlight by the texture too).
TEST(AdaptiveRender, DiffuseTexturesShareShadingScaledByTheirTexels) {
  lc::testing::TempDir dir;
  io::Image checker(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) checker.at(x, y) = Color((x + y) % 2 ? 0.8f : 0.2f);
  io::writeImage(dir.file("checker.png"), checker);
  auto sceneWith = [&](const std::string& specular) {
    return sceneFrom("SBT-raytracer 1.0\n"
                     "camera { position = (0, 3, 6); viewdir = (0, -0.5, -1); updir = (0, 1, 0); fov = 45; }\n"
                     "point_light { position = (0, 6, 1); colour = (30, 30, 30); }\n"
                     "rotate(1, 0, 0, -1.5707963, scale(10, square { material = { diffuse = map(\"" +
                     dir.file("checker.png") + "\"); specular = " + specular + "; shininess = 20; }; }))\n");
  };
  auto ev = [](const scene::Scene& s) { return lightcuts::makeBruteForce(s.lights()); };
  RenderOptions o;
  o.width = o.height = 32;
  for (const char* specular : {"(0, 0, 0)", "(0.3, 0.3, 0.3)"}) {
    SCOPED_TRACE(specular);
    auto s = sceneWith(specular);
    auto e = ev(*s);
    RenderResult shared = render(*s, *e, o);
    RenderOptions every = o;
    every.aaDecoupled = false;
    RenderResult all = render(*s, *e, every);
    ASSERT_GT(shared.stats.aaPixels, 50u);  // the checker's edges
    ASSERT_EQ(shared.stats.aaPixels, all.stats.aaPixels);
    const double perPixel = double(shared.stats.eval.shadingPoints - uint64_t(o.width * o.height)) /
                            double(shared.stats.aaPixels);
    if (std::string(specular) == "(0, 0, 0)") {
      EXPECT_LE(perPixel, 12.0);  // ~9: one per cell of the 3 x 3 grid per texel seen
    } else {
      EXPECT_GE(perPixel, 30.0);  // the fine grid
    }
    int over = 0;
    for (size_t i = 0; i < shared.image.pixels.size(); ++i) {
      const float a = luminance(shared.image.pixels[i]), b = luminance(all.image.pixels[i]);
      over += std::fabs(a - b) > 0.02f * std::max(b, 0.05f);
    }
    // (The floor's far edge, where a pixel spans a long stretch of it, is ~1.5% off: the
    // light varies within a cell there, as on a plain surface.)
    EXPECT_LE(over, int(shared.image.pixels.size() / 100)) << "pixels over 2% apart from shading every sub-sample";
  }
}

// A mirror sphere over a lit floor: its sub-samples are shaded at most once per cell of the
// 7 x 7 fine grid (per material), so 80 coverage samples cost no more shading than 48, and
// the image stays within 2% of shading all 80 on all but a few edge pixels.
TEST(AdaptiveRender, MirrorsAreShadedOncePerFineCellWithEightySamples) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 1, 5); viewdir = (0, -0.1, -1); updir = (0, 1, 0); fov = 50; }
point_light { position = (1, 4, 2); colour = (3, 3, 3); }
sphere { material = { diffuse = (0.05, 0.05, 0.05); reflective = (0.9, 0.9, 0.9); }; }
translate(0, -1, 0, scale(6, 0.1, 6, box { material = { diffuse = (0.6, 0.5, 0.4); }; }))
)");
  auto ev = lightcuts::makeBruteForce(s->lights());
  RenderOptions o;
  o.width = o.height = 40;
  o.aaSamples = 48;
  RenderResult r48 = render(*s, *ev, o);
  o.aaSamples = 80;
  RenderResult r80 = render(*s, *ev, o);
  ASSERT_GT(r80.stats.aaPixels, 40u);
  EXPECT_EQ(r80.stats.aaPixels, r48.stats.aaPixels);
  EXPECT_EQ(r80.stats.aaSubSamples, 80u * r80.stats.aaPixels);
  // The mirror's and the floor's shadings: about those of 48 sub-samples, far from 80.
  const double extra48 = double(r48.stats.eval.shadingPoints), extra80 = double(r80.stats.eval.shadingPoints);
  EXPECT_LT(extra80, 1.15 * extra48) << extra48 << " " << extra80;
  int over = 0;
  for (size_t i = 0; i < r80.image.pixels.size(); ++i) {
    const float a = luminance(r80.image.pixels[i]), b = luminance(r48.image.pixels[i]);
    over += std::fabs(a - b) > 0.1f * std::max(b, 0.05f);
  }
  EXPECT_LE(over, int(r80.image.pixels.size() / 50)) << "pixels over 10% apart from 48 sub-samples";
}

TEST(AdaptiveRender, EdgePixelsAreTheirCoverageAndOthersTheirCentre) {
  auto s = sceneFrom(kEdgeScene);
  auto ev = lightcuts::makeBruteForce(s->lights());
  RenderOptions o;
  o.width = o.height = 16;
  RenderOptions off = o;
  off.aa = AntiAliasing::Off;
  RenderResult a = render(*s, *ev, o), b = render(*s, *ev, off);
  const scene::Camera& cam = s->camera();
  auto worldX = [&](float sx) {
    Vec3 d = cam.direction(sx, 0.5f);
    return cam.eye.x + d.x * (-cam.eye.z / d.z);
  };
  int edgePixels = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      float xa = worldX(float(x) / 16), xb = worldX(float(x + 1) / 16);
      float cover = std::clamp((0.2f - std::min(xa, xb)) / std::fabs(xb - xa), 0.0f, 1.0f);
      const size_t i = size_t(y) * 16 + size_t(x);
      // A flagged pixel's 81 samples lie one in each of 81 thin columns (multi-jittered):
      // the share left of the vertical edge is its coverage to within one column.
      EXPECT_NEAR(a.image.pixels[i].x, cover, a.aaFlagged[i] ? 1.0f / 81 + 1e-3f : 0.12f) << x << "," << y;
      if (!a.aaFlagged[i]) {
        EXPECT_EQ(a.image.pixels[i], b.image.pixels[i]);
      }
      if (cover > 0.1f && cover < 0.9f) {
        ++edgePixels;
        EXPECT_TRUE(a.aaFlagged[i]);
        EXPECT_GT(std::fabs(b.image.pixels[i].x - cover), 0.12f);  // one centre sample is 0 or 1
      }
    }
  EXPECT_EQ(edgePixels, 16);  // one column
  EXPECT_EQ(a.stats.aaPixels, 32u);  // the two columns either side of the edge
  EXPECT_EQ(a.stats.aaSubSamples, 32u * 80u);  // the default 9 x 9 grid
  EXPECT_EQ(a.stats.primaryRays, 256u + 32u * 80u);  // each sub-sample's coverage ray (geometric edges)
  // With --spp 2, every pixel gets two samples and no more.
  RenderOptions fixed = o;
  fixed.spp = 2;
  RenderResult c = render(*s, *ev, fixed);
  EXPECT_EQ(c.stats.aaPixels, 0u);
  EXPECT_EQ(c.stats.primaryRays, 512u);
}

// A square shadowing a diffuse plane: lightcuts with a zero threshold is brute force, so
// the reference pixels measure no error, the flagged ones included, only if they evaluate
// the same sub-samples as the image.
TEST(AdaptiveRender, ReferencePixelsEvaluateTheSameSubSamples) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
point_light { position = (0.3, 0.2, 3); colour = (1, 1, 1); }
point_light { position = (-0.4, 0.1, 3); colour = (0.5, 0.5, 1); }
scale(10, square { material = { diffuse = (0.7, 0.7, 0.7); }; })
translate(0, 0, 1, scale(1.2, square { material = { diffuse = (0.9, 0.2, 0.2); }; }))
)");
  lightcuts::LightForest forest = lightcuts::buildLightForest(s->lights());
  lightcuts::CutOptions co;
  co.errorRatio = 0;
  auto lc = lightcuts::makeLightcuts(s->lights(), forest, co);
  RenderOptions o;
  o.width = o.height = 32;
  o.referencePixels = 32 * 32;
  RenderResult r = render(*s, *lc, o);
  EXPECT_GT(r.stats.aaPixels, 50u);
  EXPECT_EQ(r.stats.reference.pixels, 32 * 32);
  EXPECT_LT(r.stats.reference.maxRelativeError, 1e-4);
  // The image is the same at one and two threads.
  o.referencePixels = 0;
  o.threads = 1;
  RenderResult one = render(*s, *lc, o);
  o.threads = 2;
  RenderResult two = render(*s, *lc, o);
  for (size_t i = 0; i < one.image.pixels.size(); ++i) ASSERT_EQ(one.image.pixels[i], two.image.pixels[i]) << i;
}

TEST(Aovs, AlbedoNormalAndDepthOfAPlaneSeenHeadOn) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
scale(10, square { material = { diffuse = (0.5, 0.6, 0.7); }; })
)");
  RenderOptions o;
  o.width = 9;
  o.height = 7;
  PixelAovs a = primaryAovs(*s, o);
  const scene::Camera& cam = s->camera();
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      const size_t i = size_t(y) * size_t(o.width) + size_t(x);
      Vec3 d = normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height)));
      EXPECT_NEAR(a.depth[i], 5.0f / -d.z, 1e-4f);
      EXPECT_NEAR(a.normal[i].z, 1.0f, 1e-6f);
      EXPECT_EQ(a.albedo[i], Color(0.5f, 0.6f, 0.7f));
    }
}

}  // namespace
}  // namespace lc::render
