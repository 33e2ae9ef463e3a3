// Closed-form shading, mirrors, invisible panes and thread-count independence.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "io/ray_parser.h"

namespace lc::render {
namespace {

std::unique_ptr<scene::Scene> sceneFrom(const std::string& text) {
  io::SceneDesc d = io::parseRayString(text, "test.ray", "");
  return scene::Scene::build(d);
}

RenderResult renderBrute(const scene::Scene& s, int w, int h, int threads = 0, int spp = 1) {
  auto ev = lightcuts::makeBruteForce(s.lights());
  RenderOptions o;
  o.aa = AntiAliasing::Off;  // checked at pixel centres (closed forms, per-pixel comparisons)
  o.width = w;
  o.height = h;
  o.threads = threads;
  o.spp = spp;
  return render(s, *ev, o);
}

// The Phong model of the course renderer, evaluated by hand for a point on the plane z=0.
Color phongOnPlane(Vec3 p, Vec3 eye, Vec3 lightPos, Color lightColour, float a, float b, float c, Color kd,
                   Color ks, float shininess) {
  Vec3 N(0, 0, 1);
  Vec3 L = lightPos - p;
  float d = length(L);
  L = L / d;
  Vec3 V = normalize(eye - p);
  Vec3 R = normalize(N * (2 * dot(N, L)) - L);
  float atten = std::min(1.0f, 1.0f / (a + b * d + c * d * d));
  Color spec = ks * std::pow(std::max(0.0f, dot(R, V)), shininess);
  return (kd * std::max(0.0f, dot(N, L)) + spec) * atten * lightColour;
}

const char* kPlaneScene = R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
point_light { position = (1, 1.5, 2); colour = (1, 0.9, 0.8);
  constant_attenuation_coeff = 0.1; linear_attenuation_coeff = 0.2; quadratic_attenuation_coeff = 0.05; }
scale(10, square { material = { diffuse = (0.5, 0.6, 0.7); specular = (0.3, 0.3, 0.3); shininess = 10; }; })
)";

TEST(Shading, OnePointLightOverADiffuseSquareMatchesPhong) {
  auto s = sceneFrom(kPlaneScene);
  const int W = 15, H = 15;
  RenderResult r = renderBrute(*s, W, H);
  const scene::Camera& cam = s->camera();
  int checked = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      Vec3 d = normalize(cam.direction((float(x) + 0.5f) / W, (float(y) + 0.5f) / H));
      float t = -cam.eye.z / d.z;
      Vec3 p = cam.eye + d * t;
      if (std::fabs(p.x) > 5 || std::fabs(p.y) > 5) continue;
      Color expect = phongOnPlane(p, cam.eye, Vec3(1, 1.5f, 2), Color(1, 0.9f, 0.8f), 0.1f, 0.2f, 0.05f,
                                  Color(0.5f, 0.6f, 0.7f), Color(0.3f), 10);
      const Color& got = r.image.at(x, y);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], expect[c], 1e-4f) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(Shading, SpotFalloffIsCosinePowerWithCutoff) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 90; }
spot_light { position = (0, 0, 2); direction = (0, 0, -1); colour = (1, 1, 1); exponent = 4; cutoff = 30;
  constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }
scale(20, square { material = { diffuse = (1, 1, 1); }; })
)");
  const int W = 41, H = 41;
  RenderResult r = renderBrute(*s, W, H);
  const scene::Camera& cam = s->camera();
  int lit = 0, dark = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      Vec3 d = normalize(cam.direction((float(x) + 0.5f) / W, (float(y) + 0.5f) / H));
      Vec3 p = cam.eye + d * (-cam.eye.z / d.z);
      Vec3 toP = normalize(p - Vec3(0, 0, 2));
      float cosA = dot(toP, Vec3(0, 0, -1));
      float cosN = dot(Vec3(0, 0, 1), -toP);
      float expect = cosA > std::cos(30 * kPi / 180) ? std::pow(cosA, 4.0f) * cosN : 0.0f;
      if (std::fabs(cosA - std::cos(30 * kPi / 180)) < 1e-3f) continue;  // exactly on the cutoff
      ASSERT_NEAR(r.image.at(x, y).x, expect, 1e-4f) << x << "," << y;
      (expect > 0 ? lit : dark)++;
    }
  EXPECT_GT(lit, 50);
  EXPECT_GT(dark, 50);
}

TEST(Shading, AttenuationFollowsTheCourseFormula) {
  // Directly below a light at height h: atten = min(1, 1/(a + b h + c h^2)) times kd.
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 10; }
point_light { position = (0, 0, 3); colour = (1, 1, 1);
  constant_attenuation_coeff = 0.2; linear_attenuation_coeff = 0.3; quadratic_attenuation_coeff = 0.0; }
scale(10, square { material = { diffuse = (0, 1, 0); }; })
)");
  RenderResult r = renderBrute(*s, 1, 1);
  EXPECT_NEAR(r.image.at(0, 0).y, 1.0f / (0.2f + 0.3f * 3), 1e-4f);
}

TEST(Shading, ShadowsThroughGlassAreAttenuatedByItsColour) {
  // A tiny pane (index 1) between the camera, a point light straight above a white plane,
  // and the plane: the camera sees the plane through the pane, lit through the pane.
  auto a = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0.02, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 0.01; }
point_light { position = (0.02, 0, 4); colour = (1, 1, 1);
  constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }
scale(10, square { material = { diffuse = (1, 1, 1); }; })
translate(0.02, 0, 2, scale(0.01, square { material = { transmissive = (0.5, 0.25, 1); index = 1; }; }))
)");
  RenderResult r = renderBrute(*a, 1, 1, 0);
  // The pane is also seen by the camera: refracted straight through (index 1), then the
  // plane is lit through the pane: kt * (kd * light * kt).
  EXPECT_NEAR(r.image.at(0, 0).x, 0.5f * 0.5f, 1e-4f);
  EXPECT_NEAR(r.image.at(0, 0).y, 0.25f * 0.25f, 1e-4f);
  EXPECT_NEAR(r.image.at(0, 0).z, 1.0f, 1e-4f);
}

TEST(Whitted, MirrorReproducesTheReflectedScene) {
  const char* objects = R"(
translate(0.5, 0.3, %s, sphere { material = { emissive = (1, 0.2, 0.1); }; })
translate(-0.8, -0.4, %s, scale(0.8, box { material = { emissive = (0.1, 0.9, 0.3); }; }))
)";
  char withMirror[1024], reflected[1024];
  std::snprintf(withMirror, sizeof withMirror, objects, "6.5", "6.8");
  std::snprintf(reflected, sizeof reflected, objects, "-6.5", "-6.8");
  std::string cam = R"(SBT-raytracer 1.0
camera { position = (0, 0, 4); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 40; }
)";
  auto a = sceneFrom(cam + "scale(20, square { material = { reflective = (1, 1, 1); }; })\n" + withMirror);
  auto b = sceneFrom(cam + reflected);
  RenderResult ra = renderBrute(*a, 48, 48), rb = renderBrute(*b, 48, 48);
  int same = 0, lit = 0;
  for (size_t i = 0; i < ra.image.pixels.size(); ++i) {
    same += length(ra.image.pixels[i] - rb.image.pixels[i]) < 1e-5f;
    lit += !isBlack(rb.image.pixels[i]);
  }
  EXPECT_GT(lit, 100);
  EXPECT_GE(same, int(ra.image.pixels.size()) - 8);  // a few edge pixels may round differently
}

TEST(Whitted, PaneOfIndexOneIsInvisible) {
  std::string scene = R"(SBT-raytracer 1.0
camera { position = (0, 0, 6); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 40; }
translate(0, 0, -3, scale(12, square { material = { emissive = (0.3, 0.5, 0.7); }; }))
translate(0.4, 0.2, -1, sphere { material = { emissive = (0.9, 0.6, 0.1); }; })
)";
  std::string pane = "translate(0, 0, 2, scale(3, 3, 0.2, box { material = { transmissive = (1, 1, 1); index = 1; }; }))\n";
  auto a = sceneFrom(scene), b = sceneFrom(scene + pane);
  RenderResult ra = renderBrute(*a, 48, 48), rb = renderBrute(*b, 48, 48);
  int same = 0;
  for (size_t i = 0; i < ra.image.pixels.size(); ++i) same += length(ra.image.pixels[i] - rb.image.pixels[i]) < 1e-5f;
  EXPECT_GE(same, int(ra.image.pixels.size()) - 8);
}

TEST(Whitted, GlassSphereRefractsAndTotalInternalReflectionKeepsEnergyFinite) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 6); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 40; }
translate(0, 0, -3, scale(12, square { material = { emissive = (0.3, 0.5, 0.7); }; }))
sphere { material = { transmissive = (0.9, 0.9, 0.9); reflective = (0.1, 0.1, 0.1); index = 1.5; }; }
)");
  RenderResult r = renderBrute(*s, 32, 32);
  for (const Color& c : r.image.pixels) {
    ASSERT_TRUE(isFinite(c));
    ASSERT_LE(maxComponent(c), 1.0f);
  }
  // The centre sees the background through the sphere, dimmed by kt twice.
  EXPECT_NEAR(r.image.at(16, 16).z, 0.7f * 0.81f, 0.02f);
}

// Issue 29: a room of polymesh walls (two triangles per quad) seen head-on from its centre,
// lit by a point light there without falloff. Pixel centres on the image diagonals hit the
// quads' shared diagonals and the room's corner edges; every pixel is kd * cos of the angle
// between the wall's normal and the view ray (the light sits at the eye), none black.
TEST(Shading, HeadOnRoomOfQuadWallsIsLitEverywhere) {
  for (const char* fov : {"90", "120"}) {
  auto s = sceneFrom(std::string(R"(SBT-raytracer 1.0
camera { position = (0, 0, 0); viewdir = (0, 0, 1); updir = (0, 1, 0); fov = )") + fov + R"(; }
point_light { position = (0, 0, 0); colour = (1, 1, 1);
  constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }
material = { diffuse = (0.5, 0.6, 0.7); specular = (0, 0, 0); }
polymesh { points = ((-2.5,-2.5,-2.5), (2.5,-2.5,-2.5), (-2.5,2.5,-2.5), (2.5,2.5,-2.5),
                     (-2.5,-2.5,2.5), (2.5,-2.5,2.5), (-2.5,2.5,2.5), (2.5,2.5,2.5));
  faces = ((0,1,3,2), (4,6,7,5), (0,4,5,1), (2,3,7,6), (0,2,6,4), (1,5,7,3)); }
)");
  const Color kd(0.5f, 0.6f, 0.7f);
  const scene::Camera& cam = s->camera();
  for (int res : {255, 256}) {
    RenderResult r = renderBrute(*s, res, res);
    int bad = 0;
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        Vec3 d = normalize(cam.direction((float(x) + 0.5f) / float(res), (float(y) + 0.5f) / float(res)));
        // The wall hit is the one across the ray's largest component.
        float cosine = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
        const Color& got = r.image.at(x, y);
        bool ok = true;
        for (int c = 0; c < 3; ++c) ok &= std::fabs(got[c] - kd[c] * cosine) < 1e-4f;
        if (!ok && ++bad <= 5)
          ADD_FAILURE() << "fov " << fov << ", " << res << "px: pixel " << x << "," << y << " is " << got[0] << " " << got[1] << " " << got[2]
                        << ", expected " << kd[0] * cosine;
      }
    EXPECT_EQ(bad, 0) << "fov " << fov << ", " << res << "px";
  }
  }
}

TEST(Determinism, SameImageAtOneAndTwoThreads) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 1, 6); viewdir = (0, -0.2, -1); updir = (0, 1, 0); }
point_light { position = (2, 3, 2); colour = (1, 1, 1); constant_attenuation_coeff = 1; quadratic_attenuation_coeff = 0; }
point_light { position = (-2, 2, 3); colour = (0.5, 0.6, 1); constant_attenuation_coeff = 1; quadratic_attenuation_coeff = 0; }
scale(10, rotate(1, 0, 0, -1.5707963, square { material = { diffuse = (0.8, 0.8, 0.8); reflective = (0.2, 0.2, 0.2); }; }))
translate(0, 0.5, 0, sphere { material = { diffuse = (0.7, 0.2, 0.2); specular = (0.5, 0.5, 0.5); shininess = 30; }; })
)");
  RenderResult a = renderBrute(*s, 40, 30, 1, 4), b = renderBrute(*s, 40, 30, 2, 4);
  ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size());
  for (size_t i = 0; i < a.image.pixels.size(); ++i) ASSERT_EQ(a.image.pixels[i], b.image.pixels[i]) << i;
}

// Under reconstruction cuts a tile is whole cells of about 64 pixels; a small image was
// one tile (a 64 x 64 render ran on one thread). Its tiles now shrink, whole cells still,
// until there are 16 of them, from the image's size alone: the same image at any thread count.
TEST(Tiles, SmallImagesUnderReconstructionGetEnoughTilesForEveryThread) {
  auto s = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 1, 6); viewdir = (0, -0.2, -1); updir = (0, 1, 0); }
point_light { position = (2, 3, 2); colour = (1, 1, 1); constant_attenuation_coeff = 1; quadratic_attenuation_coeff = 0; }
point_light { position = (-2, 2, 3); colour = (0.5, 0.6, 1); constant_attenuation_coeff = 1; quadratic_attenuation_coeff = 0; }
point_light { position = (0, 4, -1); colour = (1, 0.8, 0.5); constant_attenuation_coeff = 1; quadratic_attenuation_coeff = 0; }
scale(10, rotate(1, 0, 0, -1.5707963, square { material = { diffuse = (0.8, 0.8, 0.8); }; }))
translate(0, 0.5, 0, sphere { material = { diffuse = (0.7, 0.2, 0.2); }; })
)");
  auto forest = lightcuts::buildLightForest(s->lights());
  auto lc = lightcuts::makeLightcuts(s->lights(), forest, lightcuts::CutOptions{});
  auto brute = lightcuts::makeBruteForce(s->lights());
  auto grid = [&](const lightcuts::LightEvaluator& ev, int w, int h, int spacing, int coarse) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.reconstructSpacing = spacing;
    o.reconstructCoarseSpacing = coarse;
    return tileGrid(o, ev);
  };
  const TileGrid small = grid(*lc, 64, 64, 2, 4);
  EXPECT_GE(small.count(), 16);
  EXPECT_EQ(small.tile % 4, 0);  // whole coarse cells
  const TileGrid tiny = grid(*lc, 24, 20, 4, 8);  // cells of 8 allow no more than 3 x 3
  EXPECT_EQ(tiny.tile, 8);
  EXPECT_EQ(grid(*lc, 512, 512, 4, 8).tile, 64);   // large images keep their tiles
  EXPECT_EQ(grid(*brute, 64, 64, 2, 4).tile, 16);  // no reconstruction: tiles of 16

  auto renderAt = [&](int threads) {
    RenderOptions o;
    o.width = 48;
    o.height = 40;
    o.threads = threads;
    o.reconstructSpacing = 2;
    o.reconstructCoarseSpacing = 4;
    return render(*s, *lc, o);
  };
  RenderResult a = renderAt(1), b = renderAt(2);
  EXPECT_GT(a.stats.eval.reconstructedPoints, 0u);
  ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size());
  for (size_t i = 0; i < a.image.pixels.size(); ++i) ASSERT_EQ(a.image.pixels[i], b.image.pixels[i]) << i;
}

TEST(Renderer, CancelledRenderIsMarkedInterrupted) {
  auto s = sceneFrom(kPlaneScene);
  auto ev = lightcuts::makeBruteForce(s->lights());
  std::atomic<bool> cancel{true};
  RenderOptions o;
  o.width = 64;
  o.height = 64;
  o.cancel = &cancel;
  RenderResult r = render(*s, *ev, o);
  EXPECT_TRUE(r.interrupted);
}

// Issue 23: a refractive index so large that refraction gives a NaN direction (inf * 0),
// and geometry so far away that hit points lie beyond what Embree accepts as a ray origin
// (~1.8e18), used to abort in Embree (ray.valid()). Such rays are dropped, not traced.
TEST(Robustness, HugeIndexAndFarHitPointsDoNotReachEmbree) {
  io::SceneDesc d = io::parseRayString(R"(SBT-raytracer 1.0
camera { position = (0, 0, 4); }
point_light { position = (0, 2, 4); }
sphere { material = { diffuse = (0.5, 0.5, 0.5); transmissive = (1, 1, 1); reflective = (0.5, 0.5, 0.5); index = 1.5; }; }
)", "test.ray", "");
  for (auto& m : d.materials) m.index.value = 1e20f;  // beyond what the parser accepts
  auto s = scene::Scene::build(d);
  RenderResult r = renderBrute(*s, 8, 8);
  for (const Color& c : r.image.pixels) EXPECT_TRUE(isFinite(c)) << c.x;

  // A mirror sphere of radius 1e30 around the camera: every hit point is ~1e30 away.
  auto far = sceneFrom(R"(SBT-raytracer 1.0
camera { position = (0, 0, 0); }
point_light { position = (0, 2, 0); }
scale(1e15, scale(1e15, sphere { material = { diffuse = (0.5, 0.5, 0.5); reflective = (0.5, 0.5, 0.5); }; }))
)");
  RenderResult f = renderBrute(*far, 8, 8);
  for (const Color& c : f.image.pixels) EXPECT_TRUE(isFinite(c)) << c.x;
}

// --error-floor auto: kAutoErrorFloorFraction of the mean luminance of its pre-pass, whose
// pixels are held to kErrorFloorPrePassError (not --error): at 32 x 32 the pre-pass is every
// pixel, so the floor is within that error (in practice far less) of the fraction of the
// mean of a brute-force image.
TEST(ErrorFloor, AutoFloorIsTheFractionOfTheMeanOfItsPrePass) {
  std::string text = R"(SBT-raytracer 1.0
camera { position = (0, 2, 6); viewdir = (0, -0.3, -1); updir = (0, 1, 0); fov = 60; }
scale(12, rotate(1, 0, 0, -1.5707963, square { material = { diffuse = (0.8, 0.8, 0.8); }; }))
translate(0, 0.5, 0, box { material = { diffuse = (0.7, 0.3, 0.2); }; })
)";
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      text += "point_light { position = (" + std::to_string(-2 + 0.2 * i) + ", 2.5, " + std::to_string(-2 + 0.2 * j) +
              "); colour = (0.01, 0.01, 0.01); }\n";
  auto s = sceneFrom(text);
  auto forest = lightcuts::buildLightForest(s->lights());
  auto lc = lightcuts::makeLightcuts(s->lights(), forest, lightcuts::CutOptions{});
  RenderOptions o;
  o.aa = AntiAliasing::Off;
  o.width = o.height = kErrorFloorGrid;
  o.errorFloor = -1;
  RenderResult r = render(*s, *lc, o);
  EXPECT_EQ(r.stats.errorFloorPixels, uint64_t(kErrorFloorGrid * kErrorFloorGrid));
  RenderResult b = renderBrute(*s, kErrorFloorGrid, kErrorFloorGrid);
  double sum = 0;
  for (const Color& c : b.image.pixels) sum += std::max(0.0f, luminance(c));
  const double want = kAutoErrorFloorFraction * sum / double(b.image.pixels.size());
  ASSERT_GT(want, 0);
  EXPECT_NEAR(r.stats.errorFloor, want, 0.02 * want);
  EXPECT_NE(r.stats.errorFloor, 0.0f);
  // The pre-pass also decides whether the render's cuts test clusters for being clear.
  EXPECT_GT(r.stats.prePass.clearTests, 0u);
  EXPECT_EQ(r.stats.clearTests, lightcuts::clearTestsPay(r.stats.prePass.clearTests, r.stats.prePass.clearedClusters));
  EXPECT_EQ(r.stats.eval.clearTests > 0, r.stats.clearTests);
}

}  // namespace
}  // namespace lc::render
