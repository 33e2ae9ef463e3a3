// Replays every input under data/regressions/<target>/ through the same entry point as
// the fuzz target that found it (fuzz/fuzz_entry.h). Each input once crashed, hung,
// leaked or failed unclearly; now it must load or fail with an lc::Error. Under
// `make test-sanitize` ASan/UBSan check the replay too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../../fuzz/cli_entry.h"
#include "../../fuzz/fuzz_entry.h"
#include "test_util.h"

namespace fs = std::filesystem;
using lc::testing::slurp;

namespace {

std::vector<std::string> inputsOf(const std::string& target) {
  std::vector<std::string> files;
  fs::path dir = lc::testing::dataPath("regressions/" + target);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && e.path().filename().string() != "README.md") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

template <class Fn>
void replay(const std::string& target, Fn&& entry) {
  for (const std::string& f : inputsOf(target)) {
    SCOPED_TRACE(f);
    std::string bytes = slurp(f);
    const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
    try {
      entry(data, bytes.size());
    } catch (const lc::Error& e) {
      // A clear error is a fine outcome; it must say something.
      EXPECT_FALSE(std::string(e.what()).empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an lc::Error: " << typeid(e).name() << ": " << e.what();
    }
  }
}

const std::string kSceneDir = lc::testing::dataPath("public-scenes");

TEST(FuzzRegression, RayParser) {
  replay("ray_parser", [](const uint8_t* d, size_t n) { lc::fuzz::parseRay(d, n, kSceneDir); });
}

TEST(FuzzRegression, ObjLoader) {
  replay("obj_loader", [](const uint8_t* d, size_t n) { lc::fuzz::loadObj(d, n); });
}

TEST(FuzzRegression, Image) {
  replay("image", [](const uint8_t* d, size_t n) { lc::fuzz::readImage(d, n); });
}

TEST(FuzzRegression, Scene) {
  replay("scene", [](const uint8_t* d, size_t n) { lc::fuzz::loadScene(d, n, kSceneDir); });
}

TEST(FuzzRegression, Compare) {
  replay("compare", [](const uint8_t* d, size_t n) { lc::fuzz::compareImages(d, n); });
}

TEST(FuzzRegression, Cli) {
  replay("cli", [](const uint8_t* d, size_t n) { lc::fuzz::parseArgs(d, n); });
}

// The CLI target's seeds parse (or are refused) cleanly: the entry point works at all.
TEST(FuzzRegression, CliSeedsParse) {
  for (const auto& e : fs::directory_iterator(lc::testing::sourceDir() + "/fuzz/seeds/cli")) {
    SCOPED_TRACE(e.path().string());
    std::string bytes = slurp(e.path().string());
    EXPECT_NO_THROW(lc::fuzz::parseArgs(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
  }
}

// The committed seeds load too (a sanity check that the entry points work at all).
TEST(FuzzRegression, SeedsLoad) {
  for (const auto& e : fs::directory_iterator(lc::testing::sourceDir() + "/fuzz/seeds/image")) {
    SCOPED_TRACE(e.path().string());
    std::string bytes = slurp(e.path().string());
    EXPECT_NO_THROW(lc::fuzz::readImage(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()))
        << "seed image does not decode";
  }
}

// The fixes for stb_image's bugs keep valid files decoding with the right values.
TEST(FuzzRegression, SixteenBitPnmKeepsItsValues) {
  lc::testing::TempDir dir;
  // 2x1 grey, maxval 65535: 0x1234 and 0xFFFF (big-endian samples).
  std::string pgm = std::string("P5\n2 1\n65535\n") + std::string("\x12\x34\xff\xff", 4);
  std::ofstream(dir.file("g.pgm"), std::ios::binary) << pgm;
  lc::io::Image g = lc::io::readImage(dir.file("g.pgm"));
  ASSERT_EQ(g.width, 2);
  ASSERT_EQ(g.height, 1);
  EXPECT_FLOAT_EQ(g.pixels[0].x, float(0x1234) / 65535.0f);
  EXPECT_FLOAT_EQ(g.pixels[0].z, float(0x1234) / 65535.0f);
  EXPECT_FLOAT_EQ(g.pixels[1].y, 1.0f);
  // 1x1 colour.
  std::string ppm = std::string("P6\n1 1\n65535\n") + std::string("\x00\x00\x80\x00\xff\xff", 6);
  std::ofstream(dir.file("c.ppm"), std::ios::binary) << ppm;
  lc::io::Image c = lc::io::readImage(dir.file("c.ppm"));
  EXPECT_FLOAT_EQ(c.pixels[0].x, 0.0f);
  EXPECT_FLOAT_EQ(c.pixels[0].y, float(0x8000) / 65535.0f);
  EXPECT_FLOAT_EQ(c.pixels[0].z, 1.0f);
}

TEST(FuzzRegression, RefusedFormatsSayWhy) {
  lc::testing::TempDir dir;
  std::ofstream(dir.file("x.gif"), std::ios::binary) << "GIF89a\x01\x00\x01\x00\x00\x00\x00;";
  try {
    lc::io::readImage(dir.file("x.gif"));
    FAIL() << "a GIF was read";
  } catch (const lc::Error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot read image '" + dir.file("x.gif") + "': GIF images are not supported");
  }
}

}  // namespace
