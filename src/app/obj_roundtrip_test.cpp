// Issue 5's round trip: `lightcuts render model.obj` and `lightcuts render` of what
// `lightcuts obj2ray model.obj` wrote give the same image (max difference <= 1e-6 in EXR),
// run through the CLI binary as a user would (its path comes from LC_BINARY, set by ctest).
// Also in-process: both paths load the same lights (object lights from Ke included) in the
// same order, and the sRGB option changes only the direct OBJ path.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "app/scene_loader.h"
#include "io/image.h"
#include "io/obj_loader.h"
#include "test_util.h"

namespace fs = std::filesystem;
using lc::testing::dataPath;
using lc::testing::TempDir;
using lc::testing::binary;
using lc::testing::slurp;

namespace lc::app {
namespace {

// Runs `lightcuts args...` in `dir`; returns the exit status, stderr in `err`.
int runCli(const std::vector<std::string>& args, const std::string& dir, std::string* err = nullptr) {
  const std::string errPath = dir + "/.stderr";
  pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    int e = open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int null = open("/dev/null", O_RDWR);
    if (e < 0 || null < 0) _exit(126);
    dup2(null, 0);
    dup2(null, 1);
    dup2(e, 2);
    std::string bin = binary();
    std::vector<std::string> copy = args;
    std::vector<char*> argv{bin.data()};
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return -1;
  if (err) *err = slurp(errPath);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

struct Difference {
  float max = 0;       // largest absolute channel difference
  double lit = 0;      // fraction of the first image's pixels brighter than 0.02
};

Difference compareExr(const std::string& a, const std::string& b) {
  io::Image x = io::readImage(a), y = io::readImage(b);
  EXPECT_EQ(x.width, y.width);
  EXPECT_EQ(x.height, y.height);
  Difference d;
  if (x.pixels.size() != y.pixels.size()) {
    d.max = INFINITY;
    return d;
  }
  size_t lit = 0;
  for (size_t i = 0; i < x.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      float dv = std::fabs(x.pixels[i][c] - y.pixels[i][c]);
      if (!(dv <= d.max)) d.max = dv;  // NaN propagates as a failure
    }
    if (maxComponent(x.pixels[i]) > 0.02f) ++lit;
  }
  d.lit = double(lit) / double(x.pixels.size());
  return d;
}

// obj2ray into a temporary folder, then both renders at 96 x 96 with brute force.
void expectSameImage(const std::string& model) {
  SCOPED_TRACE(model);
  TempDir dir;
  std::string err;
  ASSERT_EQ(runCli({"obj2ray", model, "-o", dir.file("model.ray")}, dir.path(), &err), 0) << err;
  const std::vector<std::string> common{"--width", "96", "--height", "96", "--method", "brute", "-q"};
  auto render = [&](const std::string& scene, const std::string& out) {
    std::vector<std::string> args{"render", scene, "-o", dir.file(out)};
    args.insert(args.end(), common.begin(), common.end());
    ASSERT_EQ(runCli(args, dir.path(), &err), 0) << err;
  };
  render(model, "direct.exr");
  render(dir.file("model.ray"), "converted.exr");
  Difference d = compareExr(dir.file("direct.exr"), dir.file("converted.exr"));
  EXPECT_LE(d.max, 1e-6f);
  // The model must cover part of the frame, or equal images would prove nothing.
  EXPECT_GT(d.lit, 0.05) << "the image is (nearly) black";
  std::printf("[          ] %s: max difference %g, %.0f%% of pixels lit\n",
              fs::path(model).filename().c_str(), double(d.max), 100 * d.lit);
}

TEST(ObjRoundTrip, McGuireCornellBoxLitByItsKeLight) {
  expectSameImage(dataPath("models/CornellBox-Original.obj"));
}

TEST(ObjRoundTrip, TexturedSpider) { expectSameImage(dataPath("models/assimp/spider.obj")); }

TEST(ObjRoundTrip, CubeWithTheDefaultLightRig) { expectSameImage(dataPath("models/cube.obj")); }

TEST(ObjRoundTrip, GlossyCornellBoxWithNormals) {
  expectSameImage(dataPath("models/CornellBox-Glossy.obj"));
}

// Both paths give the same light list, in the same order: the converted file has one
// trimesh per material where the OBJ has one mesh with per-triangle materials, and object
// lights are placed triangle by triangle within each luminous material either way.
TEST(ObjRoundTrip, SameLightsInTheSameOrder) {
  for (const char* rel : {"models/CornellBox-Original.obj", "models/CornellBox-Glossy.obj", "models/cube.obj"}) {
    SCOPED_TRACE(rel);
    TempDir dir;
    io::writeRayFromObj(dataPath(rel), dir.file("model.ray"), Limits{});
    LoadOptions o;
    o.quiet = true;
    LoadedScene direct = loadScene(dataPath(rel), o);
    LoadedScene converted = loadScene(dir.file("model.ray"), o);
    const auto& a = direct.scene->lights().lights;
    const auto& b = converted.scene->lights().lights;
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 0u);
    for (size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].position, b[i].position) << "light " << i;
      ASSERT_EQ(a[i].intensity, b[i].intensity) << "light " << i;
      ASSERT_EQ(a[i].direction, b[i].direction) << "light " << i;
      ASSERT_EQ(a[i].type, b[i].type) << "light " << i;
    }
    ASSERT_EQ(direct.objectLights.size(), converted.objectLights.size());
    for (size_t i = 0; i < direct.objectLights.size(); ++i) {
      EXPECT_EQ(direct.objectLights[i].lights, converted.objectLights[i].lights);
      EXPECT_EQ(direct.objectLights[i].area, converted.objectLights[i].area);
    }
  }
}

// Colour maps, the MTL's and the converted .ray's alike, are sRGB-marked and linearised only
// with LoadOptions::linearizeSrgbTextures (--tonemap srgb or filmic, the default), which
// darkens the spider's textures the same way in both; without it (--tonemap clamp) both read
// value/255 like the course renderer.
TEST(ObjRoundTrip, LinearisingSrgbTexturesAffectsBothFormatsAlike) {
  TempDir dir;
  const std::string obj = dataPath("models/assimp/spider.obj");
  io::writeRayFromObj(obj, dir.file("spider.ray"), Limits{});
  auto meanKd = [](const std::string& path, bool linearize) {
    LoadOptions o;
    o.quiet = true;
    o.linearizeSrgbTextures = linearize;
    LoadedScene ls = loadScene(path, o);
    double sum = 0;
    int n = 0;
    for (const scene::Material& m : ls.scene->materials())
      if (m.diffuse.texture) {
        Color c = m.diffuse.texture->average();
        sum += double(c.x + c.y + c.z);
        ++n;
      }
    EXPECT_GT(n, 0) << path;
    return n ? sum / n : 0.0;
  };
  double plain = meanKd(obj, false), linear = meanKd(obj, true);
  EXPECT_LT(linear, 0.9 * plain);
  EXPECT_EQ(meanKd(dir.file("spider.ray"), true), linear);
  EXPECT_EQ(meanKd(dir.file("spider.ray"), false), plain);
}

}  // namespace
}  // namespace lc::app
