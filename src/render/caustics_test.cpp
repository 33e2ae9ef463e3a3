// Caustics as many lights (issue 25): energy through a ball lens, its focus, light counted
// once through a glass slab, convergence to a photon-splatting reference, determinism, and
// the .ray keys.
#include "lights/caustics.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "core/error.h"
#include "io/ray_parser.h"
#include "lightcuts/evaluator.h"
#include "lightcuts/light_tree.h"
#include "render/renderer.h"
#include "render/tracer.h"

namespace lc {
namespace {

using lights::CausticLightKind;

std::unique_ptr<scene::Scene> sceneFrom(const std::string& text) {
  return scene::Scene::build(io::parseRayString(text, "scene.ray", ""));
}

// The ball lens of scenes/ball_lens.ray with a white floor (kd 1) and no highlights, so a
// floor point shows its irradiance (course units: kd x I cos / d^2).
constexpr float kLightHeight = 8, kBallHeight = 1.6f, kIntensity = 48, kKt = 0.9f;
std::string ballLens(bool ball) {
  return fmt::format(R"(SBT-raytracer 1.0
point_light {{ position = (0, {}, 0); colour = ({}, {}, {}); }}
rotate(1, 0, 0, -1.5707963, scale(16, square {{ material = {{ diffuse = (1, 1, 1); }}; }}))
{}
)",
                     kLightHeight, kIntensity, kIntensity, kIntensity,
                     ball ? fmt::format("translate(0, {}, 0, sphere {{ material = {{ transmissive = ({}, {}, {}); "
                                        "index = 1.5; }}; }})",
                                        kBallHeight, kKt, kKt, kKt)
                          : "");
}

// What a floor point shows (its irradiance, with kd = 1): a ray straight down onto it.
Color floorValue(const scene::Scene& s, const lightcuts::LightEvaluator& ev, float x, float z) {
  lightcuts::EvalStats stats;
  return render::traceRay(s, ev, scene::Ray{Vec3(x, 0.05f, z), Vec3(0, -1, 0), 0, kInf}, 0, stats);
}

TEST(Caustics, EnergyThroughTheBallIsWhatItInterceptsTimesTransmittance) {
  auto s = sceneFrom(ballLens(true));
  const size_t n = 1'000'000;
  auto hits = lights::traceCausticPaths(*s, lights::causticSources(s->lights()), n, 1, 10);
  Vec3d flux;
  for (const auto& h : hits) flux += h.flux;
  // The sphere subtends 2 pi (1 - sqrt(1 - r^2/d^2)) from the light; a point light of
  // intensity I emits I per steradian; both refractions weigh kt.
  double d = kLightHeight - kBallHeight;
  double omega = 2 * kPi * (1 - std::sqrt(1 - 1 / (d * d)));
  double expected = kIntensity * omega * kKt * kKt;
  EXPECT_NEAR(flux.x / expected, 1.0, 0.05) << hits.size() << " hits";
  // Every path through the ball lands on the floor, most near its axis (marginal rays
  // cross the axis above the floor, spherical aberration, and land farther out).
  size_t near = 0;
  for (const auto& h : hits) {
    ASSERT_NEAR(h.position.y, 0.0f, 1e-3f);
    near += std::hypot(h.position.x, h.position.z) < 0.5f;
  }
  EXPECT_GT(double(near), 0.7 * double(hits.size()));
  // addCaustics turns those hits into lights carrying the same power, in both models.
  for (CausticLightKind k : {CausticLightKind::Vpl, CausticLightKind::Spot}) {
    auto t = sceneFrom(ballLens(true));
    lights::CausticOptions o;
    o.paths = int(n);
    o.kind = k;
    lights::CausticInfo info = lights::addCaustics(*t, o);
    EXPECT_EQ(info.lights, hits.size());
    EXPECT_NEAR(info.power.x, flux.x, 1e-3 * flux.x);
    EXPECT_FALSE(t->shadowsThroughGlass());
  }
}

TEST(Caustics, BallLensFocusesAtLeastThreeTimesTheBareFloor) {
  auto bare = sceneFrom(ballLens(false));
  auto bareEv = lightcuts::makeBruteForce(bare->lights());
  float floorOnly = floorValue(*bare, *bareEv, 0, 0).x;
  EXPECT_NEAR(floorOnly, kIntensity / (kLightHeight * kLightHeight), 1e-3f);
  for (CausticLightKind k : {CausticLightKind::Vpl, CausticLightKind::Spot}) {
    auto s = sceneFrom(ballLens(true));
    lights::CausticOptions o;
    o.paths = 1'000'000;
    o.kind = k;
    lights::addCaustics(*s, o);
    auto ev = lightcuts::makeBruteForce(s->lights());
    // The mean over a disc of radius 0.1 under the centre.
    double sum = 0;
    int count = 0;
    for (float x = -0.1f; x <= 0.1f; x += 0.025f)
      for (float z = -0.1f; z <= 0.1f; z += 0.025f)
        if (x * x + z * z <= 0.01f) {
          sum += floorValue(*s, *ev, x, z).x;
          ++count;
        }
    double spot = sum / count;
    EXPECT_GE(spot, 3 * floorOnly) << io::causticLightKindName(k);
    // Outside the sphere's shadow the floor is lit directly, as without it.
    EXPECT_NEAR(floorValue(*s, *ev, 3, 0).x, floorValue(*bare, *bareEv, 3, 0).x, 0.01f * floorOnly);
  }
}

// Directional light through a horizontal glass slab: refraction shifts the light sideways
// without focusing it, so under the slab the floor gets exactly kt^2 of the light. Without
// caustics the kt-weighted shadow ray carries it; with caustics the caustic lights alone do
// (shadow rays stop at the glass), never both.
TEST(Caustics, LightThroughGlassIsCountedOnce) {
  const std::string text = R"(SBT-raytracer 1.0
directional_light { direction = (0, -1, 0); colour = (1, 1, 1); }
rotate(1, 0, 0, -1.5707963, scale(4, square { material = { diffuse = (1, 1, 1); }; }))
translate(0, 1, 0, scale(3, 0.2, 3, box { material = { transmissive = (0.9, 0.9, 0.9); index = 1.5; }; }))
)";
  auto plain = sceneFrom(text);
  auto plainEv = lightcuts::makeBruteForce(plain->lights());
  EXPECT_NEAR(floorValue(*plain, *plainEv, 0, 0).x, 0.81f, 1e-4f);  // the kt-weighted shadow ray
  for (CausticLightKind k : {CausticLightKind::Vpl, CausticLightKind::Spot}) {
    auto s = sceneFrom(text);
    lights::CausticOptions o;
    o.paths = 150'000;
    o.kind = k;
    lights::CausticInfo info = lights::addCaustics(*s, o);
    EXPECT_GT(info.lights, 5000u);
    auto ev = lightcuts::makeBruteForce(s->lights());
    double sum = 0;
    int count = 0;
    for (float x = -0.8f; x <= 0.8f; x += 0.4f)
      for (float z = -0.8f; z <= 0.8f; z += 0.4f) {
        sum += floorValue(*s, *ev, x, z).x;
        ++count;
      }
    EXPECT_NEAR(sum / count, 0.81, 0.81 * 0.04) << io::causticLightKindName(k);
    // Outside the slab: the directional light alone.
    EXPECT_NEAR(floorValue(*s, *ev, 1.9f, 1.9f).x, 1.0f, 0.02f);
  }
}

// The caustic image converges to a brute-force photon-splatting estimate of the same
// caustic: the mean irradiance over rings about the ball lens's axis, from the caustic
// lights, against photon counts in those rings from 16x more paths.
TEST(Caustics, BallLensConvergesToPhotonSplattingReference) {
  constexpr int kRings = 6;
  constexpr float kWidth = 0.05f;
  auto ringOf = [&](float x, float z) { return int(std::hypot(x, z) / kWidth); };
  std::array<double, kRings> ref{};
  {
    auto s = sceneFrom(ballLens(true));
    auto hits = lights::traceCausticPaths(*s, lights::causticSources(s->lights()), 8'000'000, 99, 10);
    for (const auto& h : hits)
      if (int r = ringOf(h.position.x, h.position.z); r < kRings) ref[size_t(r)] += h.flux.x;
    for (int r = 0; r < kRings; ++r) ref[size_t(r)] /= kPi * kWidth * kWidth * double((r + 1) * (r + 1) - r * r);
  }
  auto ringError = [&](int paths, CausticLightKind kind) {
    auto s = sceneFrom(ballLens(true));
    lights::CausticOptions o;
    o.paths = paths;
    o.kind = kind;
    lights::addCaustics(*s, o);
    auto ev = lightcuts::makeBruteForce(s->lights());
    std::array<double, kRings> sum{}, cnt{};
    const float step = 0.0125f;
    for (float x = -kRings * kWidth; x <= kRings * kWidth; x += step)
      for (float z = -kRings * kWidth; z <= kRings * kWidth; z += step)
        if (int r = ringOf(x + step / 2, z + step / 2); r < kRings) {
          sum[size_t(r)] += floorValue(*s, *ev, x + step / 2, z + step / 2).x;
          cnt[size_t(r)] += 1;
        }
    double err = 0, total = 0;
    for (int r = 0; r < kRings; ++r) {
      double w = double((r + 1) * (r + 1) - r * r);  // weight rings by area
      err += w * std::fabs(sum[size_t(r)] / cnt[size_t(r)] - ref[size_t(r)]);
      total += w * ref[size_t(r)];
    }
    return err / total;
  };
  for (CausticLightKind k : {CausticLightKind::Vpl, CausticLightKind::Spot}) {
    double coarse = ringError(125'000, k), fine = ringError(1'000'000, k);
    RecordProperty(std::string("ring_error_125k_") + io::causticLightKindName(k), std::to_string(coarse));
    RecordProperty(std::string("ring_error_1m_") + io::causticLightKindName(k), std::to_string(fine));
    std::printf("%s: relative ring error %.3f at 125k paths, %.3f at 1M\n", io::causticLightKindName(k), coarse,
                fine);
    EXPECT_LT(fine, coarse);
    EXPECT_LT(fine, 0.15);
  }
}

TEST(Caustics, SameLightsWhateverTheThreadCount) {
  auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    auto s = sceneFrom(ballLens(true));
    lights::CausticOptions o;
    o.paths = 200'000;
    lights::addCaustics(*s, o);
    return s->lights().lights;
  };
  auto a = run(1), b = run(4);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].position, b[i].position);
    ASSERT_EQ(a[i].intensity, b[i].intensity);
  }
}

TEST(Caustics, LightcutsMatchesBruteForceOnTheFocus) {
  auto s = sceneFrom(ballLens(true));
  lights::CausticOptions o;
  o.paths = 500'000;
  lights::addCaustics(*s, o);
  auto brute = lightcuts::makeBruteForce(s->lights());
  lightcuts::TreeBuildOptions tb;
  tb.sceneDiagonal = s->bounds().diagonal();
  lightcuts::LightForest forest = lightcuts::buildLightForest(s->lights(), tb);
  auto cuts = lightcuts::makeLightcuts(s->lights(), forest, lightcuts::CutOptions{});
  for (float x : {0.0f, 0.05f, 0.15f, 0.3f, 2.0f}) {
    float b = floorValue(*s, *brute, x, 0).x, c = floorValue(*s, *cuts, x, 0).x;
    EXPECT_NEAR(c, b, 0.03f * b + 1e-4f) << x;
  }
}

TEST(Caustics, RayKeysAndTheirErrors) {
  io::SceneDesc d = io::parseRayString("SBT-raytracer 1.0\ninstant_radiosity { caustics = 5000; caustic_lights = spot; }\n",
                                       "scene.ray", "");
  ASSERT_TRUE(d.instantRadiosity);
  EXPECT_EQ(d.instantRadiosity->caustics, 5000);
  EXPECT_EQ(d.instantRadiosity->causticLights, CausticLightKind::Spot);
  auto message = [](const std::string& text) {
    try {
      io::parseRayString(text, "scene.ray", "");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("SBT-raytracer 1.0\ninstant_radiosity { caustics = -3; }\n").find("scene.ray:2:"), std::string::npos);
  std::string m = message("SBT-raytracer 1.0\ninstant_radiosity {\n  caustic_lights = photon; }\n");
  EXPECT_NE(m.find("scene.ray:3:20:"), std::string::npos) << m;
  EXPECT_NE(m.find("\"vpl\" or \"spot\""), std::string::npos) << m;
  EXPECT_THROW(io::parseCausticLightKind("photon"), Error);
  EXPECT_EQ(io::parseCausticLightKind("vpl"), CausticLightKind::Vpl);
}

}  // namespace
}  // namespace lc
