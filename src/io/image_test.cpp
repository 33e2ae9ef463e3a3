#include "io/image.h"

#include <gtest/gtest.h>
#include <stb_image_write.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
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

TEST(Image, HugePngHeaderIsReportedAgainstTheLimit) {
  // Issue 23 #10: a PNG claiming (2^31-1)^2 pixels said "unknown image type" (stb refuses
  // over 2^24 per side and stbi_info loses the reason). Only the header is needed.
  TempDir dir;
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A,  // signature
                              0, 0, 0, 13, 'I', 'H', 'D', 'R',              // chunk length, type
                              0x7F, 0xFF, 0xFF, 0xFF, 0x7F, 0xFF, 0xFF, 0xFF,  // width, height
                              8, 2, 0, 0, 0, 0, 0, 0, 0};                  // depth, RGB, ..., CRC
  writeRaw(dir.file("huge.png"), png);
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
  // Within the pixel limit but over stb's 2^24 per side: said so, not "unknown image type".
  png[16] = 0x02, png[17] = 0, png[18] = 0, png[19] = 0;  // width 2^25
  png[20] = 0, png[21] = 0, png[22] = 0, png[23] = 1;     // height 1
  writeRaw(dir.file("wide.png"), png);
  try {
    readImage(dir.file("wide.png"), false, uint64_t(1) << 40);
    FAIL() << "expected an error";
  } catch (const ImageReadError& e) {
    EXPECT_EQ(e.kind, ImageReadError::Kind::Decode) << e.what();
    EXPECT_NE(std::string(e.what()).find("33554432x1 PNG is wider or taller than"), std::string::npos)
        << e.what();
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
std::string readError(const std::string& path) {
  try {
    readImage(path);
  } catch (const ImageReadError& e) {
    return e.what();
  }
  return "";
}

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

}  // namespace
}  // namespace lc::io
