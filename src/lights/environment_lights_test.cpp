// Environment maps and the sun/sky as directional lights (issue 24): the conversion's
// closed forms (power, irradiance of a uniform environment), the map's frame, determinism.
#include "lights/environment_lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/rng.h"
#include "io/image.h"
#include "io/ray_parser.h"

namespace lc::lights {
namespace {

scene::Environment uniformEnv(Color c) {
  io::EnvironmentDesc d;
  d.colour = c;
  return scene::Environment::build(d);
}

Vec3 randomUnit(Rng& r) {
  float z = 1 - 2 * r.uniform(), phi = 2 * kPi * r.uniform(), s = std::sqrt(std::max(0.0f, 1 - z * z));
  return Vec3(s * std::cos(phi), s * std::sin(phi), z);
}

// Irradiance / pi at a surface with normal n from the lights: what a white diffuse surface
// renders as (kd = 1), sum of max(n.w, 0) I.
Color diffuseResponse(const std::vector<Vec3>& dirs, const std::vector<Color>& I, const Vec3& n) {
  Vec3d s;
  for (size_t k = 0; k < dirs.size(); ++k) s += I[k] * std::max(0.0f, dot(n, dirs[k]));
  return s.toFloat();
}

TEST(EnvironmentLights, UniformEnvironmentLightsEveryNormalToItsRadiance) {
  scene::Environment e = uniformEnv(Color(1, 0.5f, 0.25f));
  for (int n : {1024, 4096}) {
    std::vector<Vec3> dirs;
    std::vector<Color> I;
    sampleEnvironment(e, n, 1, dirs, I);
    ASSERT_EQ(dirs.size(), size_t(n));
    // Each light stands for 4 pi / N steradians: intensity L (4 pi / N) / pi.
    for (const Color& c : I) EXPECT_NEAR(c.x, 4.0f / float(n), 1e-6f);
    Rng r(7, 7);
    double worst = 0;
    for (int k = 0; k < 500; ++k) {
      Color c = diffuseResponse(dirs, I, randomUnit(r));
      worst = std::max(worst, std::fabs(c.x - 1.0));
      EXPECT_NEAR(c.y / c.x, 0.5f, 1e-5f);
    }
    // Stratification: far below the ~2.6% (1 sigma) of 4,096 independent directions.
    EXPECT_LT(worst, n >= 4096 ? 0.004 : 0.01) << n << " lights";
  }
}

TEST(EnvironmentLights, PowerMatchesTheMapsIntegralAndLightsShareOneLuminance) {
  // A map with a bright patch, a coloured band and a black row.
  io::Image img(32, 16);
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 32; ++i)
      img.at(i, j) = j == 15 ? Color(0) : Color(0.1f + 0.02f * i, 0.2f, 0.05f * j) + (i == 5 && j == 4 ? Color(200) : Color(0));
  std::string path = (std::filesystem::temp_directory_path() / "lc_env_test_map.exr").string();
  io::writeImage(path, img);
  io::EnvironmentDesc d;
  d.map = io::TextureRef{path, {}, true};
  d.intensity = 2;
  d.colour = Color(1, 0.5f, 1);
  scene::Environment e = scene::Environment::build(d);
  double integral[3] = {0, 0, 0};
  for (int j = 0; j < 16; ++j) {
    double omega = 2 * kPi / 32 * (std::cos(kPi * j / 16) - std::cos(kPi * (j + 1) / 16));
    for (int i = 0; i < 32; ++i)
      for (int ch = 0; ch < 3; ++ch) integral[ch] += double(img.at(i, j)[ch] * d.colour[ch] * 2) * omega;
  }
  std::vector<Vec3> dirs;
  std::vector<Color> I;
  sampleEnvironment(e, 4096, 3, dirs, I);
  // Every light has the same luminance, S / (N pi); the per-pixel sums are exact, so the
  // total intensity x pi equals the integral of the map over the sphere in luminance and,
  // up to how the lights fall on the pixels, per channel.
  double Y = luminance(I[0]), sumY = 0;
  for (const Color& c : I) {
    EXPECT_NEAR(luminance(c), Y, 1e-5 * Y);
    sumY += luminance(c);
  }
  double intY = 0.2126 * integral[0] + 0.7152 * integral[1] + 0.0722 * integral[2];
  EXPECT_NEAR(sumY * kPi, intY, 1e-4 * intY);
  // The bright pixel holds most of the power: most lights go there, and they point at it.
  double u, v;
  int inPatch = 0;
  for (const Vec3& w : dirs) {
    e.coordinates(w, u, v);
    inPatch += int(u * 32) == 5 && int(v * 16) == 4;
    EXPECT_LT(v, 15.0 / 16.0 + 1e-6) << "no light in the black row";
  }
  EXPECT_GT(inPatch, 2048);
  std::filesystem::remove(path);
}

// A one-pixel sun in a 256x128 map: the thousands of lights drawn in its pixel (smaller than
// 4 pi / N) become one light carrying their summed power, pointing into the pixel.
TEST(EnvironmentLights, LightsInOneSmallPixelAreMerged) {
  io::Image img(256, 128);
  for (Color& c : img.pixels) c = Color(0.2f, 0.3f, 0.5f);
  img.at(100, 40) = Color(50000, 45000, 40000);
  std::string path = (std::filesystem::temp_directory_path() / "lc_env_test_sun.exr").string();
  io::writeImage(path, img);
  io::EnvironmentDesc d;
  d.map = io::TextureRef{path, {}, true};
  scene::Environment e = scene::Environment::build(d);
  std::vector<Vec3> dirs;
  std::vector<Color> I;
  sampleEnvironment(e, 4096, 1, dirs, I);
  std::filesystem::remove(path);
  double sunOmega = 2 * kPi / 256 * (std::cos(kPi * 40 / 128) - std::cos(kPi * 41 / 128));
  double sunY = luminance(Color(50000, 45000, 40000)) * sunOmega, total = 0;
  int inSun = 0;
  Color sunI(0);
  for (size_t k = 0; k < dirs.size(); ++k) {
    double u, v;
    e.coordinates(dirs[k], u, v);
    total += luminance(I[k]) * kPi;
    if (int(u * 256) == 100 && int(v * 128) == 40) ++inSun, sunI = I[k];
  }
  EXPECT_EQ(inSun, 1);
  EXPECT_LT(dirs.size(), 1000u);  // the sun's share of the 4,096 draws went into one light
  EXPECT_NEAR(luminance(sunI) * kPi, sunY, 1e-3 * sunY);
  double skyY = luminance(Color(0.2f, 0.3f, 0.5f)) * (4 * kPi - sunOmega);
  EXPECT_NEAR(total, sunY + skyY, 1e-4 * (sunY + skyY));
}

// A whole pixel (under 4 pi / 4,096 sr) is treated alike at every N: the one-pixel sun is one
// light of the pixel's exact power at its centroid at 1,024 lights and at 65,536 (where
// the old bound, 4 pi / N sr, split it into thousands of lights, and the images stopped
// converging: docs/BENCHMARKS.md, "Convergence").
TEST(EnvironmentLights, WholePixelIsTreatedAlikeAtEveryCount) {
  io::Image img(256, 128);
  for (Color& c : img.pixels) c = Color(0.2f, 0.3f, 0.5f);
  img.at(100, 40) = Color(50000, 45000, 40000);
  std::string path = (std::filesystem::temp_directory_path() / "lc_env_test_sun_n.exr").string();
  io::writeImage(path, img);
  io::EnvironmentDesc d;
  d.map = io::TextureRef{path, {}, true};
  scene::Environment e = scene::Environment::build(d);
  std::filesystem::remove(path);
  double sunOmega = 2 * kPi / 256 * (std::cos(kPi * 40 / 128) - std::cos(kPi * 41 / 128));
  ASSERT_GT(sunOmega, 4 * kPi / 65536);
  Color sunL(50000, 45000, 40000);
  Vec3 first;
  for (int n : {1024, 4096, 65536}) {
    std::vector<Vec3> dirs;
    std::vector<Color> I;
    sampleEnvironment(e, n, 1, dirs, I);
    EXPECT_LE(dirs.size(), size_t(n));
    int inSun = 0;
    Color sunI(0);
    Vec3 sunDir;
    for (size_t k = 0; k < dirs.size(); ++k) {
      double u, v;
      e.coordinates(dirs[k], u, v);
      if (int(u * 256) == 100 && int(v * 128) == 40) ++inSun, sunI = I[k], sunDir = dirs[k];
    }
    EXPECT_EQ(inSun, 1) << n << " lights";
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sunI[ch] * kPi, sunL[ch] * sunOmega, 1e-5 * sunL[ch] * sunOmega) << n;
    if (n == 1024) first = sunDir;
    EXPECT_EQ(sunDir, first) << "the centroid, whatever N";
  }
}

TEST(EnvironmentLights, DirectionsAndCoordinatesAreInverseWithUpAndRotate) {
  io::EnvironmentDesc d;
  d.up = Vec3(0.3f, 0.2f, -0.9f);
  d.rotateDegrees = 37;
  scene::Environment e = scene::Environment::build(d);
  Vec3 up = normalize(d.up);
  EXPECT_NEAR(dot(e.direction(0.3, 0.0), up), 1.0f, 1e-5f);  // the top row is the zenith
  EXPECT_NEAR(dot(e.direction(0.7, 1.0), up), -1.0f, 1e-5f);
  for (double u : {0.05, 0.3, 0.5, 0.77, 0.99})
    for (double v : {0.1, 0.5, 0.8}) {
      double u2, v2;
      e.coordinates(e.direction(u, v), u2, v2);
      EXPECT_NEAR(u2, u, 1e-5);
      EXPECT_NEAR(v2, v, 1e-5);
    }
  // Default frame: the centre column looks toward -z, three quarters toward +x.
  scene::Environment f = uniformEnv(Color(1));
  EXPECT_NEAR(f.direction(0.5, 0.5).z, -1.0f, 1e-6f);
  EXPECT_NEAR(f.direction(0.75, 0.5).x, 1.0f, 1e-6f);
  // rotate = 90 about +y turns -z into -x.
  io::EnvironmentDesc r;
  r.rotateDegrees = 90;
  EXPECT_NEAR(scene::Environment::build(r).direction(0.5, 0.5).x, -1.0f, 1e-6f);
}

TEST(EnvironmentLights, DeterministicForASeedAndShiftedByAnother) {
  scene::Environment e = uniformEnv(Color(1));
  std::vector<Vec3> a, b, c;
  std::vector<Color> ia, ib, ic;
  sampleEnvironment(e, 512, 5, a, ia);
  sampleEnvironment(e, 512, 5, b, ib);
  sampleEnvironment(e, 512, 6, c, ic);
  EXPECT_EQ(a.size(), 512u);
  for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k], b[k]);
  EXPECT_NE(a[0], c[0]);
}

TEST(SunSky, SkyAndSunLightAWhiteHorizontalSurfaceToTheIntensity) {
  io::EnvironmentDesc d;
  d.kind = io::EnvironmentKind::SunSky;
  d.sunDirection = Vec3(0.2f, -0.4f, 0.5f);
  d.intensity = 2;
  d.ground = Color(0.3f, 0.2f, 0.1f);
  scene::Environment e = scene::Environment::build(d);
  std::vector<Vec3> dirs;
  std::vector<Color> I;
  sampleEnvironment(e, 8192, 1, dirs, I);
  Color sky = diffuseResponse(dirs, I, Vec3(0, 1, 0));
  float sun = luminance(e.sunIrradiance()) / kPi * -normalize(d.sunDirection).y;
  EXPECT_NEAR(luminance(sky) + sun, 2.0f, 0.01f);
  EXPECT_GT(sun, luminance(sky));  // a clear day: the sun outshines the sky
  // The sky is blue: bluer than the sun, brighter near the sun than opposite it.
  Color zen = e.radiance(Vec3(0, 1, 0));
  EXPECT_GT(zen.z, zen.x);
  Vec3 toSun = -normalize(d.sunDirection);
  Vec3 nearSun = normalize(toSun + Vec3(0, 0.15f, 0)), away = normalize(Vec3(-toSun.x, toSun.y, -toSun.z));
  EXPECT_GT(luminance(e.radiance(nearSun)), 2 * luminance(e.radiance(away)));
  // Below the horizon: the ground radiance, ground x intensity.
  EXPECT_EQ(e.radiance(Vec3(0, -1, 0)), Color(0.6f, 0.4f, 0.2f));
  // The sun's disk is seen at its irradiance over its solid angle.
  EXPECT_GT(luminance(e.radiance(toSun)), 1000.0f);
}

TEST(SunSky, PreethamZenithLuminanceIsThePublishedFormula) {
  // Preetham et al. 1999, A.2: Y_z = (4.0453 T - 4.9710) tan chi - 0.2155 T + 2.4192,
  // chi = (4/9 - T/120)(pi - 2 theta_s). T = 3, theta_s = 60 degrees.
  scene::PreethamSky sky(Vec3(std::sin(kPi / 3), std::cos(kPi / 3), 0), 3);
  double chi = (4.0 / 9 - 3.0 / 120) * (kPi - 2 * kPi / 3);
  EXPECT_NEAR(sky.zenithLuminance(), (4.0453 * 3 - 4.9710) * std::tan(chi) - 0.2155 * 3 + 2.4192, 1e-4);
  EXPECT_NEAR(sky.luminance(Vec3(0, 1, 0)), sky.zenithLuminance(), 1e-3);
  // The sun through more air is redder.
  Color s = sky.sunIrradiance();
  EXPECT_GT(s.x, s.y);
  EXPECT_GT(s.y, s.z);
  EXPECT_LT(s.x, 128.0f);
}

TEST(EnvironmentLights, MissingMapIsAnErrorAtItsPlace) {
  io::SceneDesc d = io::parseRayString("SBT-raytracer 1.0\nenvironment_light {\n  map = \"nope.hdr\"; }\n", "s.ray", "");
  try {
    scene::Scene::build(d);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("s.ray:3:9: error: cannot open environment map"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace lc::lights
