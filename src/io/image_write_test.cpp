// Writing images: tone maps, exposure, and text metadata in PNG and EXR files.
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <cmath>

#include "io/image.h"
#include "io/png_text.h"
#include "test_util.h"

namespace lc::io {
namespace {

using lc::testing::TempDir;

std::vector<uint8_t> bytesOf(const std::string& path) {
  std::string s = lc::testing::slurp(path);
  return std::vector<uint8_t>(s.begin(), s.end());
}

TEST(ToneMaps, ClampSrgbAndFilmic) {
  // Clamp stores the value as it is (the course renderer); sRGB brightens mid-tones.
  EXPECT_EQ(quantize8(0.5f, ToneMap::Clamp), 128);
  EXPECT_EQ(quantize8(0.5f, ToneMap::Srgb), 188);
  EXPECT_EQ(quantize8(0.0f, ToneMap::Srgb), 0);
  EXPECT_EQ(quantize8(1.0f, ToneMap::Srgb), 255);
  EXPECT_EQ(quantize8(0.216f, ToneMap::Srgb), 128);  // linear 0.216 displays as mid-grey
  // Filmic: monotonic, black stays black, highlights roll off instead of clipping at 1.
  EXPECT_EQ(quantize8(0.0f, ToneMap::Filmic), 0);
  int prev = -1;
  for (float v : {0.01f, 0.05f, 0.18f, 0.5f, 1.0f, 2.0f, 4.0f}) {
    int q = quantize8(v, ToneMap::Filmic);
    EXPECT_GT(q, prev) << v;
    prev = q;
  }
  EXPECT_LT(quantize8(1.0f, ToneMap::Filmic), 230);
  EXPECT_GT(quantize8(4.0f, ToneMap::Filmic), 240);
  EXPECT_EQ(quantize8(INFINITY, ToneMap::Filmic), 255);
  EXPECT_EQ(quantize8(NAN, ToneMap::Filmic), 0);
  EXPECT_EQ(quantize8(-1.0f, ToneMap::Filmic), 0);
}

TEST(ToneMaps, ExposureScalesBeforeTheCurve) {
  EXPECT_EQ(quantize8(0.25f, ToneMap::Clamp, std::exp2(1.0f)), 128);
  EXPECT_EQ(quantize8(1.0f, ToneMap::Srgb, std::exp2(-2.0f)), quantize8(0.25f, ToneMap::Srgb));
  EXPECT_EQ(quantize8(0.5f, ToneMap::Filmic, 2.0f), quantize8(1.0f, ToneMap::Filmic));
}

TEST(ToneMaps, Names) {
  for (ToneMap t : {ToneMap::Clamp, ToneMap::Srgb, ToneMap::Filmic}) EXPECT_EQ(parseToneMap(toneMapName(t)), t);
  EXPECT_THROW(parseToneMap("aces"), Error);
}

TEST(WriteImage, PngStoresTheToneMappedExposedValues) {
  TempDir dir;
  Image img(2, 1);
  img.at(0, 0) = Color(0.5f, 0.25f, 0.0f);
  img.at(1, 0) = Color(2.0f, 0.107f, 1.0f);
  WriteOptions o;
  o.tonemap = ToneMap::Srgb;
  o.exposure = -1;
  writeImage(dir.file("a.png"), img, o);
  Image back = readImage(dir.file("a.png"));
  for (int x = 0; x < 2; ++x)
    for (int c = 0; c < 3; ++c)
      EXPECT_FLOAT_EQ(back.at(x, 0)[c], quantize8(img.at(x, 0)[c] * 0.5f, ToneMap::Srgb) / 255.0f) << x << c;
  EXPECT_EQ(back.at(0, 0)[0], 137 / 255.0f);  // 0.5 * 2^-1 = 0.25, sRGB-encoded
}

TEST(Crc32, MatchesPngsKnownValues) {
  const uint8_t iend[] = {'I', 'E', 'N', 'D'};
  EXPECT_EQ(crc32(iend, 4), 0xAE426082u);  // every PNG ends with this CRC
  const char* check = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const uint8_t*>(check), 9), 0xCBF43926u);  // the CRC-32 check value
}

TEST(WriteImage, PngAndExrCarryTextMetadata) {
  TempDir dir;
  Image img(3, 2);
  img.at(1, 1) = Color(0.3f, 0.6f, 0.9f);
  WriteOptions o;
  o.tonemap = ToneMap::Srgb;
  o.metadata = {{"Software", "lightcuts 9.9"}, {"Scene", "scenes/caf\xc3\xa9.ray"}, {"Command line", "render a b"}};
  writeImage(dir.file("m.png"), img, o);
  writeImage(dir.file("m.exr"), img, o);
  writeImage(dir.file("plain.png"), img, ToneMap::Srgb);

  std::vector<uint8_t> png = bytesOf(dir.file("m.png"));
  EXPECT_EQ(readPngText(png), o.metadata);
  EXPECT_TRUE(readPngText(bytesOf(dir.file("plain.png"))).empty());
  // The chunks sit after IHDR and before the pixels: decoders still read the same image.
  Image a = readImage(dir.file("m.png")), b = readImage(dir.file("plain.png"));
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (size_t i = 0; i < a.pixels.size(); ++i) EXPECT_EQ(a.pixels[i], b.pixels[i]);
  std::string text = lc::testing::slurp(dir.file("m.png"));
  EXPECT_EQ(text.find("tEXt"), 33u + 4u);  // signature 8 + IHDR 25, then the first chunk's length
  EXPECT_NE(text.find("iTXt"), std::string::npos);  // the non-ASCII value

  Imf::InputFile exr(dir.file("m.exr").c_str());
  for (const auto& [key, value] : o.metadata) {
    const auto* attr = exr.header().findTypedAttribute<Imf::StringAttribute>(key);
    ASSERT_NE(attr, nullptr) << key;
    EXPECT_EQ(attr->value(), value);
  }
  // EXR stays linear: exposure and tone map do not touch its values.
  Image e = readImage(dir.file("m.exr"));
  EXPECT_EQ(e.at(1, 1), img.at(1, 1));
}

TEST(PngText, RejectsBadKeywordsAndNonPng) {
  TempDir dir;
  writeImage(dir.file("p.png"), Image(1, 1));
  std::vector<uint8_t> png = bytesOf(dir.file("p.png"));
  EXPECT_THROW(addPngText(png, {{"", "x"}}), Error);
  EXPECT_THROW(addPngText(png, {{std::string(80, 'k'), "x"}}), Error);
  EXPECT_THROW(addPngText(png, {{" lead", "x"}}), Error);
  EXPECT_THROW(addPngText(png, {{"k", std::string("a\0b", 3)}}), Error);
  EXPECT_THROW(addPngText({1, 2, 3}, {{"k", "v"}}), Error);
  EXPECT_TRUE(readPngText({1, 2, 3}).empty());
  // A chunk whose CRC does not match is not read.
  std::vector<uint8_t> withText = addPngText(png, {{"Key", "value"}});
  ASSERT_EQ(readPngText(withText).size(), 1u);
  withText[33 + 8 + 4] ^= 1;  // a byte of the keyword
  EXPECT_TRUE(readPngText(withText).empty());
}

}  // namespace
}  // namespace lc::io
