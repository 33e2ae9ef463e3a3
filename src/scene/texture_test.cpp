#include "scene/texture.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "core/error.h"
#include "test_util.h"

namespace lc::scene {
namespace {

using lc::testing::TempDir;

void expectNear(const Color& a, const Color& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

// 4 x 2 image, top row first as io::Image stores it.
io::Image sample() {
  io::Image img(4, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) img.at(x, y) = Color(0.1f * float(x + 1), y == 0 ? 1.0f : 0.0f, 0.25f * float(x));
  return img;
}

TEST(Texture, TexelCentresGiveTheTexel) {
  io::Image img = sample();
  Texture t(img);
  EXPECT_EQ(t.width(), 4);
  EXPECT_EQ(t.height(), 2);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i) {
      Vec2 uv((float(i) + 0.5f) / 4, (float(j) + 0.5f) / 2);
      expectNear(t.lookup(uv), img.at(i, 1 - j));  // j counts from the bottom
      expectNear(t.lookup(uv), t.texel(i, j));
    }
}

TEST(Texture, VIsUp) {
  Texture t(sample());
  // The image's top row has green = 1, its bottom row green = 0.
  EXPECT_NEAR(t.lookup(Vec2(0.375f, 0.75f)).y, 1.0f, 1e-6f);  // v near 1: top
  EXPECT_NEAR(t.lookup(Vec2(0.375f, 0.25f)).y, 0.0f, 1e-6f);  // v near 0: bottom
}

TEST(Texture, HalfwayIsTheAverage) {
  io::Image img = sample();
  Texture t(img);
  // Between the centres of columns 1 and 2 (u = 1.5/4 and 2.5/4), on the top row.
  expectNear(t.lookup(Vec2(2.0f / 4, 0.75f)), (img.at(1, 0) + img.at(2, 0)) * 0.5f);
  // Between the two rows (v = 0.5), on column 0's centre.
  expectNear(t.lookup(Vec2(0.125f, 0.5f)), (img.at(0, 0) + img.at(0, 1)) * 0.5f);
  // Quarter of the way: weights 3/4, 1/4.
  expectNear(t.lookup(Vec2(1.75f / 4, 0.75f)), img.at(1, 0) * 0.75f + img.at(2, 0) * 0.25f);
}

TEST(Texture, WrapsAtTheEdges) {
  io::Image img = sample();
  Texture t(img);
  // u = 0 lies halfway between the last column's centre and the first's.
  Color edge = (img.at(3, 0) + img.at(0, 0)) * 0.5f;
  expectNear(t.lookup(Vec2(0.0f, 0.75f)), edge);
  expectNear(t.lookup(Vec2(1.0f, 0.75f)), edge);
  expectNear(t.lookup(Vec2(-3.0f, 0.75f)), edge);
  // Periodic in both directions, negative coordinates included.
  for (Vec2 uv : {Vec2(0.3f, 0.6f), Vec2(0.9f, 0.1f), Vec2(0.05f, 0.95f)}) {
    Color c = t.lookup(uv);
    expectNear(t.lookup(Vec2(uv.x + 2, uv.y - 3)), c, 1e-4f);
    expectNear(t.lookup(Vec2(uv.x - 1, uv.y + 1)), c, 1e-4f);
  }
  // v = 0 blends the bottom and top rows.
  expectNear(t.lookup(Vec2(0.125f, 0.0f)), (img.at(0, 0) + img.at(0, 1)) * 0.5f);
  // Huge and non-finite coordinates stay in range.
  Color huge = t.lookup(Vec2(1e20f, -1e20f));
  EXPECT_TRUE(isFinite(huge));
  EXPECT_TRUE(isFinite(t.lookup(Vec2(std::nanf(""), kInf))));
}

TEST(Texture, ScalarAndAverage) {
  io::Image img(2, 1);
  img.at(0, 0) = Color(0.3f, 0.6f, 0.9f);
  img.at(1, 0) = Color(0, 0, 0.3f);
  Texture t(img);
  EXPECT_NEAR(t.lookupScalar(Vec2(0.25f, 0.5f)), 0.6f, 1e-6f);
  expectNear(t.average(), Color(0.15f, 0.3f, 0.6f));
  Texture empty{io::Image()};
  EXPECT_EQ(empty.width(), 1);
  EXPECT_EQ(empty.lookup(Vec2(0.5f, 0.5f)), Color(0, 0, 0));
}

TEST(Texture, LoadsWithSrgb) {
  TempDir dir;
  io::Image img(1, 1);
  img.at(0, 0) = Color(128.0f / 255, 1, 0);
  io::writeImage(dir.file("t.png"), img);
  auto lin = Texture::load(dir.file("t.png"), true, Limits{});
  auto raw = Texture::load(dir.file("t.png"), false, Limits{});
  EXPECT_NEAR(lin->lookup(Vec2(0.5f, 0.5f)).x, 0.2158605f, 1e-6f);
  EXPECT_NEAR(raw->lookup(Vec2(0.5f, 0.5f)).x, 128.0f / 255, 1e-6f);
}

TEST(TextureCache, SharesOneDecode) {
  TempDir dir;
  io::writeImage(dir.file("checker.png"), sample());
  TextureCache cache;
  io::TextureRef a{dir.file("checker.png"), SourceLoc{"scene.ray", 3, 4}, false};
  io::TextureRef b{dir.path() + "/sub/../checker.png", SourceLoc{"scene.ray", 9, 1}, false};
  auto ta = cache.get(a, Limits{});
  EXPECT_EQ(cache.get(a, Limits{}), ta);
  EXPECT_EQ(cache.get(b, Limits{}), ta);  // same file, spelled differently
  io::TextureRef c = a;
  c.srgb = true;  // another decode of the same file
  EXPECT_NE(cache.get(c, Limits{}), ta);
  EXPECT_EQ(cache.size(), 2u);
}

TEST(TextureCache, ThreadSafe) {
  TempDir dir;
  io::writeImage(dir.file("t.png"), sample());
  TextureCache cache;
  io::TextureRef ref{dir.file("t.png"), SourceLoc{}, false};
  std::vector<std::shared_ptr<const Texture>> got(8);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < got.size(); ++i)
    threads.emplace_back([&, i] { got[i] = cache.get(ref, Limits{}); });
  for (auto& th : threads) th.join();
  for (auto& g : got) EXPECT_EQ(g, got[0]);
  EXPECT_EQ(cache.size(), 1u);
}

TEST(TextureCache, MissingTextureNamesFileAndLocation) {
  TextureCache cache;
  io::TextureRef ref{"checker.bmp", SourceLoc{"scene.ray", 12, 15}, false};
  try {
    cache.get(ref, Limits{});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "scene.ray:12:15: error: cannot open texture 'checker.bmp': No such file or directory");
    EXPECT_EQ(e.loc().line, 12);
  }
  EXPECT_EQ(cache.size(), 0u);
}

TEST(TextureCache, UndecodableAndTooLarge) {
  TempDir dir;
  { std::ofstream(dir.file("bad.png")) << "not an image"; }
  TextureCache cache;
  io::TextureRef bad{dir.file("bad.png"), SourceLoc{"s.ray", 2, 7}, false};
  try {
    cache.get(bad, Limits{});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("s.ray:2:7: error: cannot read texture '" + bad.path + "': ", 0), 0u)
        << e.what();
  }
  io::writeImage(dir.file("big.png"), sample());
  Limits small;
  small.maxTexturePixels = 7;
  io::TextureRef big{dir.file("big.png"), SourceLoc{"s.ray", 5, 1}, false};
  try {
    cache.get(big, small);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "s.ray:5:1: error: texture '" + big.path +
                                         "' is 4x2 = 8 pixels, more than --max-texture-pixels (7)");
  }
}

}  // namespace
}  // namespace lc::scene
