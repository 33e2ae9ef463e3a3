#include "io/image.h"

#include <gtest/gtest.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <zlib.h>

#include <cstdio>  // before jpeglib.h
// clang-format off
#include <jpeglib.h>
// clang-format on
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>

#include "core/error.h"
#include "core/file_util.h"
#include "test_util.h"

namespace lc::io {
namespace {

using lc::testing::TempDir;

Image gradient(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) = Color(float(x) / float(w), float(y) / float(h), float((x * 7 + y * 13) % 17) / 16.0f);
  return img;
}

void writeRaw(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<uint8_t> readRaw(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

size_t filesIn(const std::string& dir) {
  size_t n = 0;
  for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

void put16(std::vector<uint8_t>& b, uint32_t v) { b.push_back(uint8_t(v)); b.push_back(uint8_t(v >> 8)); }
void put32(std::vector<uint8_t>& b, uint32_t v) { put16(b, v & 0xffff); put16(b, v >> 16); }

// A BITMAPINFOHEADER BMP by hand. `rgb` is top row first, 3 bytes per texel;
// height < 0 stores the rows top-down, otherwise bottom-up (the usual order).
std::vector<uint8_t> makeBmp(int width, int height, int bpp, const std::vector<uint8_t>& rgb) {
  const int rows = std::abs(height);
  const int rowBytes = ((width * bpp / 8) + 3) / 4 * 4;  // padded to 4 bytes
  std::vector<uint8_t> b;
  b.push_back('B'); b.push_back('M');
  put32(b, uint32_t(54 + rowBytes * rows));
  put32(b, 0);
  put32(b, 54);                      // pixel data offset
  put32(b, 40);                      // BITMAPINFOHEADER
  put32(b, uint32_t(width));
  put32(b, uint32_t(height));        // two's complement for top-down
  put16(b, 1);
  put16(b, uint16_t(bpp));
  put32(b, 0);                       // BI_RGB
  put32(b, uint32_t(rowBytes * rows));
  put32(b, 2835); put32(b, 2835); put32(b, 0); put32(b, 0);
  for (int r = 0; r < rows; ++r) {
    int y = height < 0 ? r : rows - 1 - r;  // which image row this stored row is
    size_t start = b.size();
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = &rgb[size_t(y * width + x) * 3];
      b.push_back(p[2]); b.push_back(p[1]); b.push_back(p[0]);  // BGR
      if (bpp == 32) b.push_back(255);
    }
    while (b.size() - start < size_t(rowBytes)) b.push_back(0xEE);  // padding junk
  }
  return b;
}

void expectTexels(const Image& img, int w, int h, const std::vector<uint8_t>& rgb) {
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_FLOAT_EQ(img.at(x, y)[c], float(rgb[size_t(y * w + x) * 3 + size_t(c)]) / 255.0f)
            << "texel " << x << "," << y << " channel " << c;
}

// readImage's message, or "" when the file reads.
std::string readError(const std::string& path, uint64_t maxPixels = Limits{}.maxTexturePixels) {
  try {
    readImage(path, false, maxPixels);
  } catch (const ImageReadError& e) {
    return e.what();
  }
  return "";
}

const std::vector<uint8_t> k3x2 = {
    255, 0, 0,    0, 255, 0,    0, 0, 255,     // top row: red green blue
    10, 20, 30,   128, 64, 32,  255, 255, 255  // bottom row
};

TEST(Image, RoundTrip8BitFormats) {
  TempDir dir;
  Image img = gradient(7, 5);  // odd width: BMP rows need padding
  for (const char* ext : {"png", "ppm", "bmp"}) {
    std::string path = dir.file(std::string("img.") + ext);
    writeImage(path, img);
    Image back = readImage(path);
    ASSERT_EQ(back.width, 7) << ext;
    ASSERT_EQ(back.height, 5) << ext;
    for (size_t i = 0; i < img.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        // Exactly the quantised value, hence within half a step of the original.
        EXPECT_FLOAT_EQ(back.pixels[i][c], float(quantize8(img.pixels[i][c], ToneMap::Clamp)) / 255.0f) << ext;
        EXPECT_NEAR(back.pixels[i][c], img.pixels[i][c], 0.5f / 255.0f + 1e-6f) << ext;
      }
  }
}

TEST(Image, PpmIsBinaryP6) {
  TempDir dir;
  Image img(2, 1);
  img.at(0, 0) = Color(1, 0, 0.5f);
  img.at(1, 0) = Color(2, -1, std::numeric_limits<float>::quiet_NaN());
  writeImage(dir.file("a.ppm"), img);
  std::vector<uint8_t> bytes = readRaw(dir.file("a.ppm"));
  std::string header = "P6\n2 1\n255\n";
  ASSERT_EQ(bytes.size(), header.size() + 6);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + long(header.size())), header);
  // round(clamp(v)*255); NaN -> 0
  std::vector<uint8_t> px(bytes.begin() + long(header.size()), bytes.end());
  EXPECT_EQ(px, (std::vector<uint8_t>{255, 0, 128, 255, 0, 0}));
}

TEST(Image, SrgbToneMap) {
  EXPECT_EQ(quantize8(0.5f, ToneMap::Clamp), 128);
  EXPECT_EQ(quantize8(0.5f, ToneMap::Srgb), 188);  // 1.055*0.5^(1/2.4)-0.055 = 0.7354
  EXPECT_EQ(quantize8(0.2158605f, ToneMap::Srgb), 128);
  EXPECT_EQ(quantize8(0.001f, ToneMap::Srgb), 3);  // linear segment: 12.92*0.001*255 = 3.29
  EXPECT_EQ(quantize8(1.5f, ToneMap::Srgb), 255);
  EXPECT_EQ(quantize8(-kInf, ToneMap::Srgb), 0);
  EXPECT_EQ(quantize8(kInf, ToneMap::Clamp), 255);
  for (int i = 0; i < 256; ++i)
    EXPECT_EQ(quantize8(srgbToLinear(float(i) / 255.0f), ToneMap::Srgb), i) << i;
}

TEST(Image, ExrRoundTripIsExact) {
  TempDir dir;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  Image img(13, 9);
  for (Color& c : img.pixels) c = Color(std::exp(u(rng) * 4), u(rng), std::ldexp(u(rng), -100));
  img.at(0, 0) = Color(kInf, 0.1f, 1e-30f);
  writeImage(dir.file("x.exr"), img, ToneMap::Srgb);  // tone map is ignored for EXR
  Image back = readImage(dir.file("x.exr"));
  ASSERT_EQ(back.width, 13);
  ASSERT_EQ(back.height, 9);
  for (size_t i = 0; i < img.pixels.size(); ++i) EXPECT_EQ(back.pixels[i], img.pixels[i]) << i;
}

// Compressed on 1 or 4 threads (OpenEXR's pool), an image of many blocks of lines is the
// same file, byte for byte, and reads back exactly.
TEST(Image, ExrIsTheSameFileOnAnyThreadCount) {
  TempDir dir;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  Image img(97, 211);  // ZIP blocks hold 16 lines: 14 blocks, the last one short
  for (Color& c : img.pixels) c = Color(u(rng), u(rng) < 1 ? 0.5f : u(rng), 1.0f);
  std::vector<std::vector<uint8_t>> files;
  for (int threads : {1, 4}) {
    WriteOptions o;
    o.threads = threads;
    const std::string path = dir.file("t" + std::to_string(threads) + ".exr");
    writeImage(path, img, o);
    files.push_back(readRaw(path));
    Image back = readImage(path);
    for (size_t i = 0; i < img.pixels.size(); ++i) ASSERT_EQ(back.pixels[i], img.pixels[i]) << threads << " " << i;
  }
  EXPECT_GT(files[0].size(), 1000u);
  EXPECT_EQ(files[0], files[1]);
}

TEST(Image, ExrNanBecomesZero) {
  TempDir dir;
  Image img(1, 1);
  img.at(0, 0) = Color(std::numeric_limits<float>::quiet_NaN(), 2, 3);
  writeImage(dir.file("n.exr"), img);
  EXPECT_EQ(readImage(dir.file("n.exr")).at(0, 0), Color(0, 2, 3));
}

TEST(Image, UnknownExtension) {
  TempDir dir;
  std::string path = dir.file("x.foo");
  try {
    writeImage(path, Image(1, 1));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot write '" + path + "': unknown image format '.foo' (use .png, .ppm, .bmp or .exr)");
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_THROW(writeImage(dir.file("noext"), Image(1, 1)), Error);
  EXPECT_TRUE(isWritableImageExtension("PNG"));
  EXPECT_TRUE(isWritableImageExtension(".exr"));
  EXPECT_FALSE(isWritableImageExtension("jpg"));
  EXPECT_EQ(filesIn(dir.path()), 0u);
}

TEST(Image, EmptyImageIsAnError) {
  TempDir dir;
  EXPECT_THROW(writeImage(dir.file("e.png"), Image()), Error);
  EXPECT_EQ(filesIn(dir.path()), 0u);
}

TEST(Image, MissingDirectoryIsAnError) {
  TempDir dir;
  for (const char* ext : {"png", "exr"}) {
    std::string path = dir.file(std::string("nope/out.") + ext);
    try {
      writeImage(path, gradient(4, 4));
      FAIL() << "expected an error";
    } catch (const Error& e) {
      std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find("No such file or directory"), std::string::npos) << msg;
    }
  }
  EXPECT_EQ(filesIn(dir.path()), 0u);
}

// A write that fails half-way (the file size limit makes write() fail with EFBIG)
// must leave the existing file as it was and no temporary behind.
TEST(Image, FailedWriteLeavesExistingFileUntouched) {
  TempDir dir;
  Image small(2, 2);
  std::mt19937 rng(1);
  Image big(64, 64);
  for (Color& c : big.pixels) c = Color(float(rng() % 256) / 255.0f, float(rng() % 256) / 255.0f, 0.5f);
  for (const char* ext : {"png", "ppm", "bmp", "exr"}) {
    std::string path = dir.file(std::string("keep.") + ext);
    writeImage(path, small);
    std::vector<uint8_t> before = readRaw(path);
    ASSERT_FALSE(before.empty());

    struct rlimit old {};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
    auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim = old;
    lim.rlim_cur = 1024;  // smaller than the noisy 64x64 image in any format
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lim), 0);
    bool threw = false;
    std::string msg;
    try {
      writeImage(path, big);
    } catch (const Error& e) {
      threw = true;
      msg = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, oldHandler);

    EXPECT_TRUE(threw) << ext;
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_EQ(readRaw(path), before) << ext;
  }
  EXPECT_EQ(filesIn(dir.path()), 4u);  // no temporaries left
}

TEST(Image, ReadMissingFile) {
  TempDir dir;
  std::string path = dir.file("missing.png");
  try {
    readImage(path);
    FAIL() << "expected an error";
  } catch (const ImageReadError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot open '" + path + "': No such file or directory");
    EXPECT_EQ(e.kind, ImageReadError::Kind::Open);
  }
}

TEST(Image, ReadGarbage) {
  TempDir dir;
  std::string path = dir.file("junk.png");
  writeRaw(path, {1, 2, 3, 4, 5, 6, 7, 8, 9});
  try {
    readImage(path);
    FAIL() << "expected an error";
  } catch (const ImageReadError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot read image '" + path + "': ", 0), 0u) << e.what();
    EXPECT_EQ(e.kind, ImageReadError::Kind::Decode);
  }
  // A truncated EXR is reported the same way, not as a crash.
  writeImage(dir.file("t.exr"), gradient(16, 16));
  std::vector<uint8_t> exr = readRaw(dir.file("t.exr"));
  exr.resize(exr.size() / 2);
  writeRaw(dir.file("t.exr"), exr);
  EXPECT_THROW(readImage(dir.file("t.exr")), ImageReadError);
}

TEST(Image, SizeLimitCheckedBeforeDecoding) {
  TempDir dir;
  for (const char* ext : {"png", "exr"}) {
    std::string path = dir.file(std::string("s.") + ext);
    writeImage(path, gradient(3, 2));
    EXPECT_NO_THROW(readImage(path, false, 6));
    try {
      readImage(path, false, 5);
      FAIL() << "expected an error";
    } catch (const ImageReadError& e) {
      EXPECT_EQ(e.kind, ImageReadError::Kind::TooLarge);
      EXPECT_EQ(e.width, 3);
      EXPECT_EQ(e.height, 2);
      EXPECT_NE(std::string(e.what()).find("limit of 5"), std::string::npos) << e.what();
    }
  }
}

// A PNG signature and an IHDR chunk (with its CRC, which libpng checks), then nothing or (with
// idat) the start of an IDAT chunk: where libpng's png_read_info stops and the size is checked.
std::vector<uint8_t> pngHeaderOnly(uint32_t width, uint32_t height, bool idat = false) {
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A, 0, 0, 0, 13};
  const size_t type = png.size();
  for (uint32_t v : {0x49484452u /* IHDR */, width, height})
    for (int shift = 24; shift >= 0; shift -= 8) png.push_back(uint8_t(v >> shift));
  png.insert(png.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, no filter, not interlaced
  const uint32_t crc = uint32_t(crc32(0, png.data() + type, uInt(png.size() - type)));
  for (int shift = 24; shift >= 0; shift -= 8) png.push_back(uint8_t(crc >> shift));
  if (idat) png.insert(png.end(), {0, 0, 0x10, 0, 'I', 'D', 'A', 'T'});
  return png;
}

TEST(Image, HugePngHeaderIsReportedAgainstTheLimit) {
  // Issue 23 #10: a PNG claiming (2^31-1)^2 pixels is reported against the limit (the file
  // ends after IHDR: the size is the first problem, and it is known from IHDR).
  TempDir dir;
  writeRaw(dir.file("huge.png"), pngHeaderOnly(0x7FFFFFFF, 0x7FFFFFFF));
  try {
    readImage(dir.file("huge.png"), false, 1000);
    FAIL() << "expected an error";
  } catch (const ImageReadError& e) {
    EXPECT_EQ(e.kind, ImageReadError::Kind::TooLarge) << e.what();
    EXPECT_EQ(e.width, 2147483647);
    EXPECT_EQ(e.height, 2147483647);
    EXPECT_NE(std::string(e.what()).find("2147483647x2147483647 = 4611686014132420609 pixels, more than "
                                         "the limit of 1000"),
              std::string::npos)
        << e.what();
  }
  // 2^25 x 1 within the pixel limit: libpng has no cap of its own below 2^31 (stb_image had
  // 2^24), so what is wrong with this file is that it ends.
  writeRaw(dir.file("wide.png"), pngHeaderOnly(1u << 25, 1));
  EXPECT_EQ(readError(dir.file("wide.png"), uint64_t(1) << 40),
            "cannot read image '" + dir.file("wide.png") + "': truncated PNG: the file ends before the image data does");
  // 20000 x 20000 pixels is refused from the header, before a pixel buffer is allocated (the
  // default texture limit is 16384^2): the image data is not looked at.
  writeRaw(dir.file("big.png"), pngHeaderOnly(20000, 20000, true));
  try {
    readImage(dir.file("big.png"));
    FAIL() << "expected an error";
  } catch (const ImageReadError& e) {
    EXPECT_EQ(e.kind, ImageReadError::Kind::TooLarge) << e.what();
  }
}

TEST(Image, Bmp24BottomUpWithRowPadding) {
  TempDir dir;
  std::vector<uint8_t> bmp = makeBmp(3, 2, 24, k3x2);
  ASSERT_EQ(bmp.size(), 54u + 2 * 12);  // 9 bytes of texels padded to 12
  writeRaw(dir.file("a.bmp"), bmp);
  expectTexels(readImage(dir.file("a.bmp")), 3, 2, k3x2);
}

TEST(Image, Bmp24TopDown) {
  TempDir dir;
  writeRaw(dir.file("a.bmp"), makeBmp(3, -2, 24, k3x2));
  expectTexels(readImage(dir.file("a.bmp")), 3, 2, k3x2);
}

TEST(Image, Bmp32) {
  TempDir dir;
  writeRaw(dir.file("a.bmp"), makeBmp(3, 2, 32, k3x2));
  expectTexels(readImage(dir.file("a.bmp")), 3, 2, k3x2);
}

TEST(Image, PngDecodesToKnownTexels) {
  TempDir dir;
  ASSERT_TRUE(stbi_write_png(dir.file("rgb.png").c_str(), 3, 2, 3, k3x2.data(), 9));
  expectTexels(readImage(dir.file("rgb.png")), 3, 2, k3x2);

  // RGBA: alpha is ignored.
  std::vector<uint8_t> rgba = {10, 20, 30, 0, 200, 100, 50, 128};
  ASSERT_TRUE(stbi_write_png(dir.file("rgba.png").c_str(), 2, 1, 4, rgba.data(), 8));
  expectTexels(readImage(dir.file("rgba.png")), 2, 1, {10, 20, 30, 200, 100, 50});

  // Grey and grey+alpha expand to RGB.
  std::vector<uint8_t> grey = {0, 77, 255};
  ASSERT_TRUE(stbi_write_png(dir.file("g.png").c_str(), 3, 1, 1, grey.data(), 3));
  expectTexels(readImage(dir.file("g.png")), 3, 1, {0, 0, 0, 77, 77, 77, 255, 255, 255});
  std::vector<uint8_t> ga = {77, 0, 255, 9};
  ASSERT_TRUE(stbi_write_png(dir.file("ga.png").c_str(), 2, 1, 2, ga.data(), 4));
  expectTexels(readImage(dir.file("ga.png")), 2, 1, {77, 77, 77, 255, 255, 255});
}

TEST(Image, ReadsPgmAndTga) {
  TempDir dir;
  std::string pgm = "P5\n2 1\n255\n";
  std::vector<uint8_t> bytes(pgm.begin(), pgm.end());
  bytes.push_back(51);
  bytes.push_back(204);
  writeRaw(dir.file("a.pgm"), bytes);
  expectTexels(readImage(dir.file("a.pgm")), 2, 1, {51, 51, 51, 204, 204, 204});
  ASSERT_TRUE(stbi_write_tga(dir.file("a.tga").c_str(), 3, 2, 3, k3x2.data()));
  expectTexels(readImage(dir.file("a.tga")), 3, 2, k3x2);
}

TEST(Image, HdrStaysLinear) {
  TempDir dir;
  std::vector<float> px = {4.0f, 0.5f, 0.25f};
  ASSERT_TRUE(stbi_write_hdr(dir.file("a.hdr").c_str(), 1, 1, 3, px.data()));
  Image img = readImage(dir.file("a.hdr"), /*srgb=*/true);
  EXPECT_NEAR(img.at(0, 0).x, 4.0f, 0.02f);
  EXPECT_NEAR(img.at(0, 0).y, 0.5f, 0.005f);
  EXPECT_NEAR(img.at(0, 0).z, 0.25f, 0.003f);
}

TEST(Image, SrgbLinearisation) {
  TempDir dir;
  std::vector<uint8_t> px = {0, 10, 128, 255, 255, 255};
  ASSERT_TRUE(stbi_write_png(dir.file("s.png").c_str(), 2, 1, 3, px.data(), 6));
  Image lin = readImage(dir.file("s.png"), true);
  EXPECT_FLOAT_EQ(lin.at(0, 0).x, 0.0f);
  EXPECT_NEAR(lin.at(0, 0).y, 10.0 / 255.0 / 12.92, 1e-7);           // linear segment
  EXPECT_NEAR(lin.at(0, 0).z, 0.2158605, 1e-6);                      // ((128/255+.055)/1.055)^2.4
  EXPECT_FLOAT_EQ(lin.at(1, 0).x, 1.0f);
  Image raw = readImage(dir.file("s.png"), false);
  EXPECT_FLOAT_EQ(raw.at(0, 0).z, 128.0f / 255.0f);
}

TEST(Image, ReadDirectoryIsAnError) {
  TempDir dir;
  EXPECT_THROW(readImage(dir.path()), ImageReadError);
}

// Issue 23: truncated images decoded as valid (stb reads missing samples as zeros or stale
// memory): `compare a.png trunc.ppm` reported RMSE 0. The data length is checked against
// the header now, for each format.

std::vector<uint8_t> bytesOf(const std::string& header, size_t samples) {
  std::vector<uint8_t> b(header.begin(), header.end());
  b.resize(b.size() + samples, 100);
  return b;
}

TEST(ImageTruncated, PpmAndPgm) {
  TempDir dir;
  writeRaw(dir.file("t.ppm"), bytesOf("P6\n32 32\n255\n", 100));
  EXPECT_NE(readError(dir.file("t.ppm")).find("truncated PNM data: 100 bytes of samples, the header needs 3072"),
            std::string::npos)
      << readError(dir.file("t.ppm"));
  writeRaw(dir.file("t.pgm"), bytesOf("P5 32 32 255\n", 1023));
  EXPECT_NE(readError(dir.file("t.pgm")).find("truncated PNM data"), std::string::npos);
  writeRaw(dir.file("ok.ppm"), bytesOf("P6\n32 32\n255\n", 3072));
  writeRaw(dir.file("ok.pgm"), bytesOf("P5 32 32 255\n", 1024));
  EXPECT_EQ(readError(dir.file("ok.ppm")), "");
  EXPECT_EQ(readError(dir.file("ok.pgm")), "");
  EXPECT_EQ(readImage(dir.file("ok.ppm")).width, 32);
}

// stb_image's PNM header parsing is lax: a missing number reads as 0 and the character after
// the maxval is skipped whatever it is. "P58015 1" then a non-digit (found by the compare
// fuzz target, data/regressions/compare/pnm_header_without_maxval.pgm) decoded as an 8015x1
// image of uninitialised memory, which compared unequal to itself. Such headers are refused.
TEST(ImageTruncated, PnmHeadersStbWouldMisread) {
  TempDir dir;
  const std::string numbers = "bad PNM header (expected the width, height and maxval as decimal numbers)";
  const std::string space = "bad PNM header (expected one whitespace character after the maxval)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {std::string("P58015 1\xa9" "7"), numbers},        // the fuzzer's input: no maxval
      {"P6 2 2\n", numbers},                             // no maxval, end of file
      {"P5 2x2 255\n" + std::string(4, 'a'), numbers},   // no height
      {"P5\n", numbers},                                 // no numbers at all
      {"P5 2 2 255", space},                             // nothing after the maxval
      {"P5 2 2 255x" + std::string(4, 'a'), space},       // not whitespace after the maxval
      {"P5 1 1 65535x" + std::string(2, 'a'), space},     // 16-bit (was "bad PNM header")
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string f = dir.file("h" + std::to_string(i) + ".pgm");
    writeRaw(f, std::vector<uint8_t>(cases[i].first.begin(), cases[i].first.end()));
    EXPECT_EQ(readError(f), "cannot read image '" + f + "': " + cases[i].second) << cases[i].first;
  }
  // Well-formed headers still read, comments included.
  writeRaw(dir.file("c.pgm"), bytesOf("P5\n# a comment\n2 1\n255\n", 2));
  EXPECT_EQ(readError(dir.file("c.pgm")), "");
  writeRaw(dir.file("t.ppm"), bytesOf("P6\t2\r1 255\r", 6));
  EXPECT_EQ(readError(dir.file("t.ppm")), "");
}

TEST(ImageTruncated, Bmp) {
  TempDir dir;
  std::vector<uint8_t> rgb(size_t(8 * 8 * 3), 200);
  std::vector<uint8_t> bmp = makeBmp(8, 8, 24, rgb);
  writeRaw(dir.file("ok.bmp"), bmp);
  EXPECT_EQ(readError(dir.file("ok.bmp")), "");
  bmp.resize(bmp.size() - 30);
  writeRaw(dir.file("t.bmp"), bmp);
  EXPECT_NE(readError(dir.file("t.bmp")).find("truncated BMP data"), std::string::npos) << readError(dir.file("t.bmp"));
  // Top-down rows (negative height) are checked the same way.
  std::vector<uint8_t> topDown = makeBmp(8, -8, 24, rgb);
  topDown.resize(60);
  writeRaw(dir.file("td.bmp"), topDown);
  EXPECT_NE(readError(dir.file("td.bmp")).find("truncated BMP data"), std::string::npos) << readError(dir.file("td.bmp"));
}

std::vector<uint8_t> tgaHeader(int type, int w, int h) {
  std::vector<uint8_t> b(18, 0);
  b[2] = uint8_t(type);
  b[12] = uint8_t(w);
  b[14] = uint8_t(h);
  b[16] = 24;
  return b;
}

TEST(ImageTruncated, Tga) {
  TempDir dir;
  std::vector<uint8_t> raw = tgaHeader(2, 4, 4);
  raw.resize(18 + 48, 90);
  writeRaw(dir.file("ok.tga"), raw);
  EXPECT_EQ(readError(dir.file("ok.tga")), "");
  EXPECT_EQ(readImage(dir.file("ok.tga")).width, 4);
  raw.resize(18 + 10);
  writeRaw(dir.file("t.tga"), raw);
  EXPECT_NE(readError(dir.file("t.tga")).find("truncated TGA data"), std::string::npos) << readError(dir.file("t.tga"));

  // Run-length: one run of 16 pixels is whole; a run of 8 and nothing after is not.
  std::vector<uint8_t> rle = tgaHeader(10, 4, 4);
  rle.push_back(0x8f);
  rle.insert(rle.end(), {10, 20, 30});
  writeRaw(dir.file("ok_rle.tga"), rle);
  EXPECT_EQ(readError(dir.file("ok_rle.tga")), "");
  rle = tgaHeader(10, 4, 4);
  rle.push_back(0x87);
  rle.insert(rle.end(), {10, 20, 30});
  writeRaw(dir.file("t_rle.tga"), rle);
  EXPECT_NE(readError(dir.file("t_rle.tga")).find("truncated TGA data"), std::string::npos)
      << readError(dir.file("t_rle.tga"));
}


// ---- PNG through libpng, JPEG through libjpeg-turbo (issue 30) ----------------------------

// A PNG built by hand: IHDR, optional PLTE/tRNS, one IDAT of the given scanlines (filter
// byte 0 added here), IEND. `rows` holds the packed samples of each row, big-endian.
void pngChunk(std::vector<uint8_t>& png, const char* type, const std::vector<uint8_t>& data) {
  for (int shift = 24; shift >= 0; shift -= 8) png.push_back(uint8_t(data.size() >> shift));
  const size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  const uint32_t crc = uint32_t(crc32(0, png.data() + start, uInt(png.size() - start)));
  for (int shift = 24; shift >= 0; shift -= 8) png.push_back(uint8_t(crc >> shift));
}
std::vector<uint8_t> makePng(uint32_t w, uint32_t h, int depth, int colorType,
                             const std::vector<std::vector<uint8_t>>& rows,
                             const std::vector<uint8_t>& plte = {}, const std::vector<uint8_t>& trns = {}) {
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  std::vector<uint8_t> ihdr;
  for (uint32_t v : {w, h})
    for (int shift = 24; shift >= 0; shift -= 8) ihdr.push_back(uint8_t(v >> shift));
  ihdr.insert(ihdr.end(), {uint8_t(depth), uint8_t(colorType), 0, 0, 0});
  pngChunk(png, "IHDR", ihdr);
  if (!plte.empty()) pngChunk(png, "PLTE", plte);
  if (!trns.empty()) pngChunk(png, "tRNS", trns);
  std::vector<uint8_t> raw;
  for (const auto& r : rows) {
    raw.push_back(0);
    raw.insert(raw.end(), r.begin(), r.end());
  }
  uLongf n = compressBound(uLong(raw.size()));
  std::vector<uint8_t> z(n);
  EXPECT_EQ(compress2(z.data(), &n, raw.data(), uLong(raw.size()), 9), Z_OK);
  z.resize(n);
  pngChunk(png, "IDAT", z);
  pngChunk(png, "IEND", {});
  return png;
}

TEST(ImagePng, WrittenByStbReadByLibpng) {
  // Every channel count stb writes, random texels: libpng gives back exactly what was written
  // (grey replicated to RGB, alpha dropped).
  TempDir dir;
  std::mt19937 rng(30);
  const int w = 37, h = 23;
  for (int comp = 1; comp <= 4; ++comp) {
    std::vector<uint8_t> px(size_t(w * h * comp));
    for (uint8_t& v : px) v = uint8_t(rng());
    const std::string path = dir.file("rt" + std::to_string(comp) + ".png");
    ASSERT_TRUE(stbi_write_png(path.c_str(), w, h, comp, px.data(), w * comp));
    std::vector<uint8_t> rgb;
    for (int i = 0; i < w * h; ++i)
      for (int c = 0; c < 3; ++c) rgb.push_back(px[size_t(i * comp + (comp <= 2 ? 0 : c))]);
    expectTexels(readImage(path), w, h, rgb);
  }
  // And what writeImage writes (stb) reads back as the quantised values.
  Image img = gradient(64, 48);
  writeImage(dir.file("g.png"), img);
  Image back = readImage(dir.file("g.png"));
  ASSERT_EQ(back.pixels.size(), img.pixels.size());
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_FLOAT_EQ(back.pixels[i][c], float(quantize8(img.pixels[i][c], ToneMap::Clamp)) / 255.0f);
}

TEST(ImagePng, SixteenBitGreyAndRgb) {
  TempDir dir;
  // 16-bit RGB, 2x1: value / 65535 per channel, big-endian samples.
  writeRaw(dir.file("rgb16.png"),
           makePng(2, 1, 16, 2, {{0x12, 0x34, 0x00, 0x00, 0xFF, 0xFF, 0x80, 0x00, 0x00, 0x01, 0xAB, 0xCD}}));
  Image rgb = readImage(dir.file("rgb16.png"));
  ASSERT_EQ(rgb.width, 2);
  EXPECT_FLOAT_EQ(rgb.at(0, 0).x, float(0x1234) / 65535.0f);
  EXPECT_FLOAT_EQ(rgb.at(0, 0).y, 0.0f);
  EXPECT_FLOAT_EQ(rgb.at(0, 0).z, 1.0f);
  EXPECT_FLOAT_EQ(rgb.at(1, 0).x, float(0x8000) / 65535.0f);
  EXPECT_FLOAT_EQ(rgb.at(1, 0).y, 1.0f / 65535.0f);
  EXPECT_FLOAT_EQ(rgb.at(1, 0).z, float(0xABCD) / 65535.0f);
  // 16-bit grey + alpha: grey replicated, alpha dropped; srgb linearises the 16-bit value.
  writeRaw(dir.file("ga16.png"), makePng(1, 2, 16, 4, {{0x40, 0x00, 0x12, 0x34}, {0xFF, 0xFF, 0x00, 0x00}}));
  Image ga = readImage(dir.file("ga16.png"), true);
  ASSERT_EQ(ga.height, 2);
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(ga.at(0, 0)[c], srgbToLinear(float(0x4000) / 65535.0f));
    EXPECT_FLOAT_EQ(ga.at(0, 1)[c], 1.0f);
  }
}

TEST(ImagePng, PaletteTransparencyAndLowBitGrey) {
  TempDir dir;
  // 2-bit palette with a tRNS entry: RGB from the palette, the transparency ignored.
  const std::vector<uint8_t> plte = {255, 0, 0, 0, 255, 0, 0, 0, 255, 7, 8, 9};
  writeRaw(dir.file("pal.png"), makePng(4, 1, 2, 3, {{0b00011011}}, plte, {0, 128}));
  expectTexels(readImage(dir.file("pal.png")), 4, 1, {255, 0, 0, 0, 255, 0, 0, 0, 255, 7, 8, 9});
  // 1-, 2- and 4-bit grey scale to 0..255 as stb_image did (v * 255 / (2^bits - 1)).
  writeRaw(dir.file("g1.png"), makePng(2, 1, 1, 0, {{0b01000000}}));
  expectTexels(readImage(dir.file("g1.png")), 2, 1, {0, 0, 0, 255, 255, 255});
  writeRaw(dir.file("g2.png"), makePng(2, 1, 2, 0, {{0b01100000}}));
  expectTexels(readImage(dir.file("g2.png")), 2, 1, {85, 85, 85, 170, 170, 170});
  writeRaw(dir.file("g4.png"), makePng(2, 1, 4, 0, {{0x3F}}));
  expectTexels(readImage(dir.file("g4.png")), 2, 1, {51, 51, 51, 255, 255, 255});
}

TEST(ImagePng, InterlacedMatchesItsNonInterlacedTwin) {
  // The Adam7 seed and its non-interlaced twin (both made by ImageMagick) decode alike.
  const std::string seeds = lc::testing::sourceDir() + "/fuzz/seeds/image/";
  Image a = readImage(seeds + "a_adam7.png"), b = readImage(seeds + "a_rgb.png");
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(a.pixels[i][c], b.pixels[i][c]) << i;
}

TEST(ImagePng, TruncatedAndCorruptAreRefusedNamingTheFile) {
  TempDir dir;
  writeImage(dir.file("ok.png"), gradient(64, 64));
  std::vector<uint8_t> png = readRaw(dir.file("ok.png"));
  for (size_t keep : {png.size() / 2, size_t(40), png.size() - 5}) {
    std::vector<uint8_t> cut(png.begin(), png.begin() + long(keep));
    writeRaw(dir.file("t.png"), cut);
    try {
      readImage(dir.file("t.png"));
      FAIL() << "a PNG cut at " << keep << " bytes was read";
    } catch (const ImageReadError& e) {
      EXPECT_EQ(e.kind, ImageReadError::Kind::Decode);
      EXPECT_EQ(e.path, dir.file("t.png"));
      EXPECT_EQ(std::string(e.what()), "cannot read image '" + dir.file("t.png") + "': " + e.reason);
      EXPECT_EQ(e.reason, "truncated PNG: the file ends before the image data does") << keep;
    }
  }
  // A flipped bit in the image data: zlib's check fails first (the chunk's CRC would next).
  std::vector<uint8_t> bad = png;
  bad[bad.size() / 2] ^= 0x10;
  writeRaw(dir.file("c.png"), bad);
  EXPECT_EQ(readError(dir.file("c.png")).rfind("cannot read image '" + dir.file("c.png") + "': corrupt PNG (IDAT: ", 0), 0u)
      << readError(dir.file("c.png"));
  // A flipped bit in IHDR: its CRC (stb_image checked no CRC).
  bad = png;
  bad[17] ^= 0x01;
  writeRaw(dir.file("h.png"), bad);
  EXPECT_EQ(readError(dir.file("h.png")), "cannot read image '" + dir.file("h.png") + "': corrupt PNG (IHDR: CRC error)");
}

// A JPEG written by libjpeg itself (CMYK needs it: stb_image_write writes YCbCr only).
std::vector<uint8_t> makeJpeg(int w, int h, int comps, J_COLOR_SPACE in, J_COLOR_SPACE out,
                              const std::vector<uint8_t>& px, bool progressive = false, bool arithmetic = false) {
  jpeg_compress_struct c{};
  jpeg_error_mgr err{};
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  unsigned char* buf = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &buf, &size);
  c.image_width = JDIMENSION(w);
  c.image_height = JDIMENSION(h);
  c.input_components = comps;
  c.in_color_space = in;
  jpeg_set_defaults(&c);
  jpeg_set_colorspace(&c, out);
  jpeg_set_quality(&c, 100, TRUE);
  for (int i = 0; i < c.num_components; ++i) c.comp_info[i].h_samp_factor = c.comp_info[i].v_samp_factor = 1;
  if (progressive) jpeg_simple_progression(&c);
  c.arith_code = arithmetic ? TRUE : FALSE;
  jpeg_start_compress(&c, TRUE);
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<uint8_t*>(&px[size_t(c.next_scanline) * size_t(w * comps)]);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  std::vector<uint8_t> bytes(buf, buf + size);
  jpeg_destroy_compress(&c);
  std::free(buf);
  return bytes;
}

TEST(ImageJpeg, BaselineProgressiveAndGrey) {
  // Flat 16x16 blocks, no chroma subsampling: quality 100 keeps them within a step or two.
  TempDir dir;
  const int w = 32, h = 16;
  std::vector<uint8_t> rgb(size_t(w * h * 3)), grey(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t v[3] = {uint8_t(x < 16 ? 200 : 40), uint8_t(90), uint8_t(x < 16 ? 10 : 230)};
      for (int c = 0; c < 3; ++c) rgb[size_t((y * w + x) * 3 + c)] = v[c];
      grey[size_t(y * w + x)] = uint8_t(x < 16 ? 30 : 220);
    }
  for (bool progressive : {false, true}) {
    writeRaw(dir.file("c.jpg"), makeJpeg(w, h, 3, JCS_RGB, JCS_YCbCr, rgb, progressive));
    Image img = readImage(dir.file("c.jpg"));
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(img.at(x, y)[c] * 255.0f, rgb[size_t((y * w + x) * 3 + c)], 3.0f) << x << "," << y;
  }
  writeRaw(dir.file("g.jpg"), makeJpeg(w, h, 1, JCS_GRAYSCALE, JCS_GRAYSCALE, grey));
  Image g = readImage(dir.file("g.jpg"));
  for (int x = 0; x < w; ++x)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.at(x, 5)[c] * 255.0f, grey[size_t(5 * w + x)], 1.0f);
}

TEST(ImageJpeg, CmykAndYcckAreConvertedAsStbDid) {
  // Adobe CMYK (stored inverted, as Photoshop writes it): R = C * K / 255, and so on. YCCK
  // is the same after libjpeg's conversion. stb_image reads the same files within a step.
  TempDir dir;
  const int w = 16, h = 16;
  std::vector<uint8_t> cmyk(size_t(w * h * 4));
  for (size_t i = 0; i < size_t(w * h); ++i) {
    cmyk[4 * i + 0] = 255;
    cmyk[4 * i + 1] = 128;
    cmyk[4 * i + 2] = 20;
    cmyk[4 * i + 3] = 200;
  }
  const float want[3] = {200.0f, 100.4f, 15.7f};
  for (J_COLOR_SPACE space : {JCS_CMYK, JCS_YCCK}) {
    writeRaw(dir.file("k.jpg"), makeJpeg(w, h, 4, JCS_CMYK, space, cmyk));
    Image img = readImage(dir.file("k.jpg"));
    int sw = 0, sh = 0, sc = 0;
    unsigned char* stb = stbi_load(dir.file("k.jpg").c_str(), &sw, &sh, &sc, 3);
    ASSERT_TRUE(stb) << stbi_failure_reason();
    for (size_t i = 0; i < img.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(img.pixels[i][c] * 255.0f, want[c], 2.0f) << space;
        EXPECT_NEAR(img.pixels[i][c] * 255.0f, float(stb[3 * i + size_t(c)]), 1.0f) << space;
      }
    stbi_image_free(stb);
  }
}

TEST(ImageJpeg, TruncatedAndCorruptAreRefusedNamingTheFile) {
  TempDir dir;
  Image img = gradient(64, 64);
  std::vector<uint8_t> rgb(size_t(64 * 64 * 3));
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = quantize8(img.pixels[i][c], ToneMap::Clamp);
  ASSERT_TRUE(stbi_write_jpg(dir.file("ok.jpg").c_str(), 64, 64, 3, rgb.data(), 90));
  EXPECT_EQ(readError(dir.file("ok.jpg")), "");
  std::vector<uint8_t> jpg = readRaw(dir.file("ok.jpg"));

  // Cut in the image data or in the headers: the file ends early (libjpeg alone would fill
  // the rest of the image with grey and call it a warning).
  for (size_t keep : {jpg.size() / 2, size_t(300), jpg.size() - 10}) {
    writeRaw(dir.file("t.jpg"), std::vector<uint8_t>(jpg.begin(), jpg.begin() + long(keep)));
    try {
      readImage(dir.file("t.jpg"));
      FAIL() << "a JPEG cut at " << keep << " bytes was read";
    } catch (const ImageReadError& e) {
      EXPECT_EQ(e.kind, ImageReadError::Kind::Decode);
      EXPECT_EQ(std::string(e.what()), "cannot read image '" + dir.file("t.jpg") + "': " + e.reason);
      EXPECT_EQ(e.reason, "truncated JPEG: the file ends before the image data does") << keep;
    }
  }

  // A Huffman table (DHT, FF C4) whose code counts add up to more than 256 (what the fuzzer
  // found in stb_image): refused.
  std::vector<uint8_t> bad = jpg;
  size_t dht = 2;
  while (dht + 1 < bad.size() && !(bad[dht] == 0xFF && bad[dht + 1] == 0xC4)) ++dht;
  ASSERT_LT(dht + 21, bad.size());
  for (size_t k = 0; k < 16; ++k) bad[dht + 5 + k] = 0x40;  // 16 lengths x 64 codes
  writeRaw(dir.file("dht.jpg"), bad);
  EXPECT_EQ(readError(dir.file("dht.jpg")),
            "cannot read image '" + dir.file("dht.jpg") + "': corrupt JPEG (Bogus Huffman table definition)");

  // Garbage in the entropy-coded data: a marker in the middle of the scan.
  bad = jpg;
  size_t sos = 2;
  while (sos + 1 < bad.size() && !(bad[sos] == 0xFF && bad[sos + 1] == 0xDA)) ++sos;
  const size_t mid = sos + (bad.size() - sos) / 2;
  bad[mid] = 0xFF;
  bad[mid + 1] = 0xD9;  // EOI
  writeRaw(dir.file("scan.jpg"), bad);
  const std::string msg = readError(dir.file("scan.jpg"));
  EXPECT_EQ(msg.rfind("cannot read image '" + dir.file("scan.jpg") + "': corrupt JPEG (", 0), 0u) << msg;

  // FF, then no start-of-image marker.
  writeRaw(dir.file("x.jpg"), {0xFF, 0xD9, 0xFF, 0x00, 0x01});
  EXPECT_EQ(readError(dir.file("x.jpg")),
            "cannot read image '" + dir.file("x.jpg") + "': corrupt JPEG (Not a JPEG file: starts with 0xff 0xd9)");
}

TEST(ImageJpeg, ArithmeticCodingReadsTwelveBitIsRefused) {
  TempDir dir;
  std::vector<uint8_t> grey(64 * 8);
  for (size_t i = 0; i < grey.size(); ++i) grey[i] = uint8_t(i % 64 < 32 ? 50 : 180);
  // Arithmetic-coded (stb_image refused these): decodes.
  writeRaw(dir.file("a.jpg"), makeJpeg(64, 8, 1, JCS_GRAYSCALE, JCS_GRAYSCALE, grey, false, true));
  Image a = readImage(dir.file("a.jpg"));
  EXPECT_NEAR(a.at(3, 3).y * 255.0f, 50.0f, 1.0f);
  EXPECT_NEAR(a.at(60, 3).y * 255.0f, 180.0f, 1.0f);
  // The frame header says 12 bits per sample: refused, saying why.
  std::vector<uint8_t> jpg = makeJpeg(64, 8, 1, JCS_GRAYSCALE, JCS_GRAYSCALE, grey);
  size_t sof = 2;
  while (sof + 4 < jpg.size() && !(jpg[sof] == 0xFF && jpg[sof + 1] == 0xC0)) ++sof;
  ASSERT_LT(sof + 4, jpg.size());
  jpg[sof + 4] = 12;
  writeRaw(dir.file("p12.jpg"), jpg);
  EXPECT_EQ(readError(dir.file("p12.jpg")), "cannot read image '" + dir.file("p12.jpg") +
                                                "': JPEG feature not supported (Unsupported JPEG data precision 12)");
}

// The decoders agree with stb_image on the valid PNG and JPEG files of the repository (the
// textures of data/ and scenes/, the image seeds): PNG byte for byte (8 and 16 bits), JPEG
// within 3 of 255 (the IDCT and the chroma upsampling round differently; libjpeg's defaults
// are the closest of its choices).
TEST(ImageDecoders, AgreeWithStbOnTheRepositorysImages) {
  std::vector<std::string> files;
  for (const char* dir : {"data", "scenes", "fuzz/seeds/image"})
    for (const auto& e : std::filesystem::recursive_directory_iterator(lc::testing::sourceDir() + "/" + dir)) {
      std::string ext = e.path().extension().string();
      if (e.path().string().find("/regressions/") != std::string::npos) continue;
      if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") files.push_back(e.path().string());
    }
  ASSERT_GE(files.size(), 20u);
  int jpegs = 0;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    const bool jpeg = std::filesystem::path(f).extension() != ".png";
    Image img = readImage(f);
    int w = 0, h = 0, comp = 0;
    if (stbi_is_16_bit(f.c_str())) {
      std::unique_ptr<stbi_us, void (*)(void*)> d(stbi_load_16(f.c_str(), &w, &h, &comp, 3), stbi_image_free);
      ASSERT_TRUE(d);
      ASSERT_EQ(img.width, w);
      ASSERT_EQ(img.height, h);
      for (size_t i = 0; i < size_t(w) * size_t(h) * 3; ++i)
        ASSERT_EQ(img.pixels[i / 3][int(i % 3)], float(d.get()[i]) / 65535.0f) << i;
      continue;
    }
    std::unique_ptr<stbi_uc, void (*)(void*)> d(stbi_load(f.c_str(), &w, &h, &comp, 3), stbi_image_free);
    ASSERT_TRUE(d);
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    jpegs += jpeg;
    for (size_t i = 0; i < size_t(w) * size_t(h) * 3; ++i) {
      const float v = img.pixels[i / 3][int(i % 3)] * 255.0f;
      if (jpeg)
        ASSERT_NEAR(v, float(d.get()[i]), 3.0f) << i;
      else
        ASSERT_EQ(img.pixels[i / 3][int(i % 3)], float(d.get()[i]) / 255.0f) << i;
    }
  }
  EXPECT_GE(jpegs, 6);
}

}  // namespace
}  // namespace lc::io
