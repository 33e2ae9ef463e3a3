#include "io/image.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include "core/file_util.h"

namespace lc::io {

namespace {

constexpr const char* kFormatsHint = "(use .png, .ppm, .bmp or .exr)";

std::string normalizeExt(std::string ext) {
  if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Writes `bytes` to `tmp`; errors name the final `path`, which is what the user asked for.
void writeBytes(const std::string& tmp, const std::string& path, const std::vector<uint8_t>& bytes) {
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw Error("cannot write '" + path + "': " + std::strerror(errno));
  size_t n = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), f);
  int writeErr = n == bytes.size() ? 0 : (errno ? errno : EIO);
  if (std::fclose(f) != 0 && writeErr == 0) writeErr = errno ? errno : EIO;
  if (writeErr != 0) throw Error("cannot write '" + path + "': " + std::strerror(writeErr));
}

std::vector<uint8_t> toBytes(const Image& img, ToneMap tonemap) {
  std::vector<uint8_t> out(img.pixels.size() * 3);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) out[3 * i + size_t(c)] = quantize8(img.pixels[i][c], tonemap);
  return out;
}

void appendToVector(void* ctx, void* data, int size) {
  auto* v = static_cast<std::vector<uint8_t>*>(ctx);
  auto* p = static_cast<const uint8_t*>(data);
  v->insert(v->end(), p, p + size);
}

std::vector<uint8_t> encodePpm(const Image& img, const std::vector<uint8_t>& rgb) {
  std::string header = "P6\n" + std::to_string(img.width) + " " + std::to_string(img.height) + "\n255\n";
  std::vector<uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), rgb.begin(), rgb.end());
  return out;
}

void writeExr(const std::string& tmp, const std::string& path, const Image& img) {
  // NaN -> 0 as in the 8-bit formats; infinities are kept (EXR can hold them).
  std::vector<Color> px(img.pixels);
  for (Color& c : px)
    for (int k = 0; k < 3; ++k)
      if (std::isnan(c[k])) c[k] = 0;
  try {
    Imf::Header header(img.width, img.height);
    // 32-bit float channels: the round trip is exact (half would lose precision).
    for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(Color), ys = sizeof(Color) * size_t(img.width);
    char* base = reinterpret_cast<char*>(px.data());
    fb.insert("R", Imf::Slice(Imf::FLOAT, base + offsetof(Color, x), xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + offsetof(Color, y), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + offsetof(Color, z), xs, ys));
    Imf::OutputFile file(tmp.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(img.height);
  } catch (const std::exception& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
}

[[noreturn]] void throwOpen(const std::string& path, const std::string& reason) {
  throw ImageReadError(ImageReadError::Kind::Open, path, reason,
                       "cannot open '" + path + "': " + reason);
}
[[noreturn]] void throwDecode(const std::string& path, const std::string& reason) {
  throw ImageReadError(ImageReadError::Kind::Decode, path, reason,
                       "cannot read image '" + path + "': " + reason);
}
void checkSize(const std::string& path, int w, int h, uint64_t maxPixels) {
  if (w <= 0 || h <= 0) throwDecode(path, "empty image");
  uint64_t n = uint64_t(w) * uint64_t(h);
  if (n > maxPixels) {
    std::string reason = std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(n) +
                         " pixels, more than the limit of " + std::to_string(maxPixels);
    throw ImageReadError(ImageReadError::Kind::TooLarge, path, reason,
                         "image '" + path + "' is " + reason, w, h);
  }
}

Image readExr(const std::string& path, uint64_t maxPixels) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    checkSize(path, w, h, maxPixels);
    const Imf::ChannelList& channels = file.header().channels();
    bool hasRgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
    bool hasY = channels.findChannel("Y") != nullptr;
    if (!hasRgb && !hasY) throwDecode(path, "no R, G, B or Y channel");

    Image img(w, h);
    const size_t xs = sizeof(Color), ys = sizeof(Color) * size_t(w);
    char* base = reinterpret_cast<char*>(img.pixels.data());
    Imf::FrameBuffer fb;
    // Slice::Make handles a data window that does not start at (0,0). Missing channels
    // are filled with 0; a luminance-only file is read into R and copied to G and B.
    if (hasRgb) {
      fb.insert("R", Imf::Slice::Make(Imf::FLOAT, base + offsetof(Color, x), dw, xs, ys));
      fb.insert("G", Imf::Slice::Make(Imf::FLOAT, base + offsetof(Color, y), dw, xs, ys));
      fb.insert("B", Imf::Slice::Make(Imf::FLOAT, base + offsetof(Color, z), dw, xs, ys));
    } else {
      fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, base + offsetof(Color, x), dw, xs, ys));
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    if (!hasRgb)
      for (Color& c : img.pixels) c.y = c.z = c.x;
    return img;
  } catch (const ImageReadError&) {
    throw;
  } catch (const std::exception& e) {
    throwDecode(path, e.what());
  }
}

// stb sets a reason with every failure, but a null would crash std::string.
std::string stbiReason() {
  const char* r = stbi_failure_reason();
  return r ? r : "unknown error";
}

struct StbiFree {
  void operator()(void* p) const { stbi_image_free(p); }
};
struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};

const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

}  // namespace

float srgbToLinear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

uint8_t quantize8(float v, ToneMap tonemap) {
  if (std::isnan(v)) return 0;
  v = std::clamp(v, 0.0f, 1.0f);
  if (tonemap == ToneMap::Srgb) v = linearToSrgb(v);
  return uint8_t(std::lround(v * 255.0f));
}

bool isWritableImageExtension(const std::string& ext) {
  std::string e = normalizeExt(ext);
  return e == "png" || e == "ppm" || e == "bmp" || e == "exr";
}

void writeImage(const std::string& path, const Image& image, ToneMap tonemap) {
  const std::string ext = fileExtension(path);
  if (!isWritableImageExtension(ext)) {
    if (ext.empty()) throw Error("cannot write '" + path + "': no image format extension " + kFormatsHint);
    // Report the extension as the user spelled it.
    std::string given = std::filesystem::path(path).extension().string();
    throw Error("cannot write '" + path + "': unknown image format '" + given + "' " + kFormatsHint);
  }
  if (image.width <= 0 || image.height <= 0)
    throw Error("cannot write '" + path + "': empty image (" + std::to_string(image.width) + "x" +
                std::to_string(image.height) + ")");
  if (image.pixels.size() != size_t(image.width) * size_t(image.height))
    throw Error("cannot write '" + path + "': pixel count does not match " +
                std::to_string(image.width) + "x" + std::to_string(image.height));

  if (ext == "exr") {
    writeFileAtomically(path, [&](const std::string& tmp) { writeExr(tmp, path, image); });
    return;
  }
  // Encode in memory first so that file errors come from our own writes (with errno)
  // rather than from stb's silent 0 return.
  std::vector<uint8_t> rgb = toBytes(image, tonemap);
  std::vector<uint8_t> encoded;
  if (ext == "ppm") {
    encoded = encodePpm(image, rgb);
  } else {
    int ok = ext == "png" ? stbi_write_png_to_func(appendToVector, &encoded, image.width, image.height, 3,
                                                   rgb.data(), image.width * 3)
                          : stbi_write_bmp_to_func(appendToVector, &encoded, image.width, image.height, 3,
                                                   rgb.data());
    if (!ok) throw Error("cannot write '" + path + "': the " + ext + " encoder failed");
  }
  writeFileAtomically(path, [&](const std::string& tmp) { writeBytes(tmp, path, encoded); });
}

Image readImage(const std::string& path, bool srgb, uint64_t maxPixels) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throwOpen(path, "it is a directory");
  // A device or FIFO could block or never end (e.g. map("/dev/stdin")).
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throwOpen(path, "not a regular file");
  std::unique_ptr<FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) throwOpen(path, std::strerror(errno));

  // Dispatch on the magic number, so a misnamed EXR still reads.
  unsigned char magic[4] = {0, 0, 0, 0};
  size_t got = std::fread(magic, 1, 4, f.get());
  std::rewind(f.get());
  if (got == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01) {
    f.reset();
    return readExr(path, maxPixels);
  }

  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_file(f.get(), &w, &h, &comp)) throwDecode(path, stbiReason());
  // stbi_info reports a top-down BMP's height as negative (as stored); the decoder flips it.
  if (h < 0 && h != std::numeric_limits<int>::min()) h = -h;
  checkSize(path, w, h, maxPixels);

  // Ask for 3 channels: stb expands grey and drops alpha.
  if (stbi_is_hdr_from_file(f.get())) {
    std::unique_ptr<float, StbiFree> data(stbi_loadf_from_file(f.get(), &w, &h, &comp, 3));
    if (!data) throwDecode(path, stbiReason());
    Image img(w, h);
    for (size_t i = 0; i < img.pixels.size(); ++i)
      img.pixels[i] = Color(data.get()[3 * i], data.get()[3 * i + 1], data.get()[3 * i + 2]);
    return img;
  }
  if (stbi_is_16_bit_from_file(f.get())) {
    std::unique_ptr<stbi_us, StbiFree> data(stbi_load_from_file_16(f.get(), &w, &h, &comp, 3));
    if (!data) throwDecode(path, stbiReason());
    Image img(w, h);
    for (size_t i = 0; i < img.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        float v = float(data.get()[3 * i + size_t(c)]) / 65535.0f;
        img.pixels[i][c] = srgb ? srgbToLinear(v) : v;
      }
    return img;
  }
  std::unique_ptr<stbi_uc, StbiFree> data(stbi_load_from_file(f.get(), &w, &h, &comp, 3));
  if (!data) throwDecode(path, stbiReason());
  Image img(w, h);
  const auto& table = srgbTable();
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      stbi_uc v = data.get()[3 * i + size_t(c)];
      img.pixels[i][c] = srgb ? table[v] : float(v) / 255.0f;
    }
  return img;
}

}  // namespace lc::io
