// Replays every input under data/regressions/<target>/ through the same entry point as
// the fuzz target that found it (fuzz/fuzz_entry.h). Each input once crashed, hung,
// leaked or failed unclearly; now it must load or fail with an lc::Error. Under
// `make test-sanitize` ASan/UBSan check the replay too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
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

// Each known-bad image is refused with a message that names the file and says what is wrong
// (since issue 30 the JPEGs and the PNG by libjpeg-turbo and libpng, not by guards before stb).
TEST(FuzzRegression, KnownBadImagesAreRefusedClearly) {
  const std::map<std::string, std::string> reasons = {
      {"hdr_rle_zero_count.hdr", "corrupt HDR (bad run-length data)"},
      {"jpeg_dht_overflow.jpg", "corrupt JPEG (Bogus Huffman table definition)"},
      {"jpeg_dht_overflow_fill_bytes.jpg", "corrupt JPEG (Not a JPEG file: starts with 0xff 0xff)"},
      {"jpeg_progressive_shift.jpg", "corrupt JPEG (51 extraneous bytes before marker 0xdb)"},
      {"jpeg_undefined_huffman_table.jpg", "corrupt JPEG (63 extraneous bytes before marker 0xc2)"},
      {"png_empty_idat.png", "corrupt PNG (IHDR: CRC error)"},
      {"pnm_header_int_overflow.pgm", "bad PNM header (a number larger than 2147483647)"},
      // libpng allocated its row buffers (3 GB) before the size was checked.
      {"png_row_buffers_before_size_check.png", ""},
  };
  size_t refused = 0;
  for (const std::string& f : inputsOf("image")) {
    SCOPED_TRACE(f);
    const std::string name = fs::path(f).filename().string();
    if (name == "pnm16_channel_conversion.pgm") {  // a valid 16-bit PGM: it reads (1x8)
      EXPECT_EQ(lc::io::readImage(f).height, 8);
      continue;
    }
    ASSERT_EQ(reasons.count(name), 1u) << "add the expected message of " << name;
    try {
      lc::io::readImage(f);
      ADD_FAILURE() << "read";
    } catch (const lc::Error& e) {
      if (reasons.at(name).empty())
        EXPECT_EQ(std::string(e.what()), "image '" + f + "' is 989855746x2 = 1979711492 pixels, more than the limit of 268435456");
      else
        EXPECT_EQ(std::string(e.what()), "cannot read image '" + f + "': " + reasons.at(name));
      ++refused;
    }
  }
  EXPECT_EQ(refused, reasons.size());
}

// compare's inputs: each file is one image, compared with itself. pnm_header_without_maxval.pgm
// ("P58015 1", then a non-digit) was read by stb_image as an 8015x1 image of uninitialised
// memory (the maxval missing, read as 0): it compared unequal to itself.
TEST(FuzzRegression, CompareInputsAreRefusedClearly) {
  const std::map<std::string, std::string> reasons = {
      {"pnm_header_without_maxval.pgm", "bad PNM header (expected the width, height and maxval as decimal numbers)"},
  };
  size_t refused = 0;
  for (const std::string& f : inputsOf("compare")) {
    SCOPED_TRACE(f);
    const std::string name = fs::path(f).filename().string();
    ASSERT_EQ(reasons.count(name), 1u) << "add the expected message of " << name;
    try {
      lc::io::readImage(f);
      ADD_FAILURE() << "read";
    } catch (const lc::Error& e) {
      EXPECT_EQ(std::string(e.what()), "cannot read image '" + f + "': " + reasons.at(name));
      ++refused;
    }
  }
  EXPECT_EQ(refused, reasons.size());
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
