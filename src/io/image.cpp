#include "io/image.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <png.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cstdio>  // before jpeglib.h, which uses FILE
// clang-format off
#include <jpeglib.h>
#include <jerror.h>
// clang-format on

#include <algorithm>
#include <array>
#include <cerrno>
#include <csetjmp>
#include <cstddef>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/file_util.h"
#include "core/memory_budget.h"
#include "io/png_text.h"

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
  if (!f) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
  size_t n = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), f);
  int writeErr = n == bytes.size() ? 0 : (errno ? errno : EIO);
  if (std::fclose(f) != 0 && writeErr == 0) writeErr = errno ? errno : EIO;
  if (writeErr != 0) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(writeErr));
}

std::vector<uint8_t> toBytes(const Image& img, ToneMap tonemap, float exposure) {
  std::vector<uint8_t> out(img.pixels.size() * 3);
  const float scale = std::exp2(exposure);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) out[3 * i + size_t(c)] = quantize8(img.pixels[i][c], tonemap, scale);
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

void writeExr(const std::string& tmp, const std::string& path, const Image& img, const TextMetadata& metadata,
              const std::vector<WriteOptions::Channel>& channels, int threads) {
  // NaN -> 0 as in the 8-bit formats; infinities are kept (EXR can hold them). Copied only
  // when there is a NaN to clear (25 MB at 1920x1080).
  const bool hasNan = std::any_of(img.pixels.begin(), img.pixels.end(), [](const Color& c) {
    return std::isnan(c.x) || std::isnan(c.y) || std::isnan(c.z);
  });
  std::vector<Color> cleared;
  if (hasNan) {
    cleared = img.pixels;
    for (Color& c : cleared)
      for (int k = 0; k < 3; ++k)
        if (std::isnan(c[k])) c[k] = 0;
  }
  const std::vector<Color>& px = hasNan ? cleared : img.pixels;
  try {
    Imf::Header header(img.width, img.height);
    // 32-bit float channels: the round trip is exact (half would lose precision).
    for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    for (const WriteOptions::Channel& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(Color), ys = sizeof(Color) * size_t(img.width);
    char* base = reinterpret_cast<char*>(const_cast<Color*>(px.data()));  // read only
    fb.insert("R", Imf::Slice(Imf::FLOAT, base + offsetof(Color, x), xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + offsetof(Color, y), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + offsetof(Color, z), xs, ys));
    for (const WriteOptions::Channel& c : channels)
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.values.data())),
                                   sizeof(float), sizeof(float) * size_t(img.width)));
    // The blocks are compressed on OpenEXR's global thread pool (without one, each is
    // compressed inline, whatever the file's thread count).
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    {
      static std::mutex poolMutex;
      std::lock_guard<std::mutex> lock(poolMutex);
      if (Imf::globalThreadCount() < threads) Imf::setGlobalThreadCount(threads);
    }
    Imf::OutputFile file(tmp.c_str(), header, threads);
    file.setFrameBuffer(fb);
    file.writePixels(img.height);
  } catch (const std::exception& e) {
    throw Error("cannot write " + quoteInput(path) + ": " + e.what());
  }
}

[[noreturn]] void throwOpen(const std::string& path, const std::string& reason) {
  throw ImageReadError(ImageReadError::Kind::Open, path, reason,
                       "cannot open " + quoteInput(path) + ": " + reason);
}
[[noreturn]] void throwDecode(const std::string& path, const std::string& reason) {
  throw ImageReadError(ImageReadError::Kind::Decode, path, reason,
                       "cannot read image " + quoteInput(path) + ": " + reason);
}
void checkSize(const std::string& path, int w, int h, uint64_t maxPixels) {
  if (w <= 0 || h <= 0) throwDecode(path, "empty image");
  uint64_t n = uint64_t(w) * uint64_t(h);
  if (n > maxPixels) {
    std::string reason = std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(n) +
                         " pixels, more than the limit of " + std::to_string(maxPixels);
    throw ImageReadError(ImageReadError::Kind::TooLarge, path, reason,
                         "image " + quoteInput(path) + " is " + reason, w, h);
  }
  // Counted against --max-memory before decoding, across every image of the run (textures,
  // environment maps, compare's inputs): float texels and the decoder's buffer.
  const uint64_t bytes = n * memory_cost::kTexel;
  if (!processBudget().tryReserve(bytes)) {
    std::string msg = processBudget().overBudget(
        bytes, "the " + std::to_string(w) + "x" + std::to_string(h) + " pixels of " + quoteInput(path));
    throw ImageReadError(ImageReadError::Kind::Memory, path, msg, msg, w, h);
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

}  // namespace

std::vector<float> readExrChannel(const std::string& path, const std::string& name, int& width, int& height) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    width = dw.max.x - dw.min.x + 1;
    height = dw.max.y - dw.min.y + 1;
    if (!file.header().channels().findChannel(name)) throwDecode(path, "no channel '" + name + "'");
    std::vector<float> v(size_t(width) * size_t(height));
    Imf::FrameBuffer fb;
    fb.insert(name, Imf::Slice::Make(Imf::FLOAT, v.data(), dw, sizeof(float), sizeof(float) * size_t(width)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return v;
  } catch (const ImageReadError&) {
    throw;
  } catch (const std::exception& e) {
    throwDecode(path, e.what());
  }
}

namespace {

// stb sets a reason with every failure, but a null would crash std::string.
std::string stbiReason() {
  const char* r = stbi_failure_reason();
  return r ? r : "unknown error";
}

std::vector<uint8_t> readAll(FILE* f) {
  std::vector<uint8_t> b;
  uint8_t buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) b.insert(b.end(), buf, buf + n);
  std::rewind(f);
  return b;
}

const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

// libpng and libjpeg report errors through a callback that must not return: it longjmps back
// to the setjmp of the function that called into the library. The functions holding a setjmp
// (pngInfo, pngSetup, pngPixels, jpegHeader, jpegPixels) keep only plain data in their frames;
// every C++ object (the pixel buffers, the Image) belongs to their callers, so a jump skips no
// destructor. The library structs are freed by PngRead's / JpegRead's destructors on every path.

// ---- PNG: libpng ----------------------------------------------------------------------------

struct PngRead {
  png_structp png = nullptr;
  png_infop info = nullptr;
  FILE* file = nullptr;
  int passes = 1;          // 7 for an interlaced PNG
  bool truncated = false;  // the read callback hit the end of the file
  char message[256] = "";
  ~PngRead() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

void pngError(png_structp png, png_const_charp msg) {
  auto* r = static_cast<PngRead*>(png_get_error_ptr(png));
  std::snprintf(r->message, sizeof r->message, "%s", msg ? msg : "unknown error");
  png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}  // ancillary problems: libpng skips the chunk
void pngReadData(png_structp png, png_bytep data, size_t n) {
  auto* r = static_cast<PngRead*>(png_get_io_ptr(png));
  if (std::fread(data, 1, n, r->file) != n) {
    r->truncated = !std::ferror(r->file);
    png_error(png, r->truncated ? "the file ends early" : "read error");
  }
}

// Reads the chunks up to the image data (the size is then known: the caller checks it before
// pngSetup, whose png_read_update_info allocates row buffers).
bool pngInfo(PngRead& r) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  // libpng's default caps each side at 10^6; the caller's pixel limit is the one to apply.
  png_set_user_limits(r.png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  png_read_info(r.png, r.info);
  return true;
}

// The transforms that give what stb_image gave when asked for 3 channels: palette -> RGB, grey
// of 1/2/4 bits -> 8 bits (scaled to 0..255), grey -> RGB, alpha (and tRNS) dropped; 8 and 16
// bits stay as they are (16-bit samples big-endian). No gamma or colour-space transform (stb
// applied none).
bool pngSetup(PngRead& r) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  const int colorType = png_get_color_type(r.png, r.info), depth = png_get_bit_depth(r.png, r.info);
  if (colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(r.png);
  if (colorType == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(r.png);
  if (colorType == PNG_COLOR_TYPE_GRAY || colorType == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(r.png);
  png_set_strip_alpha(r.png);
  r.passes = png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  return true;
}

// Row by row into the caller's buffer (no array of row pointers: as many as the rows); an
// interlaced image passes over the rows once per pass.
bool pngPixels(PngRead& r, uint8_t* data, size_t rowBytes, uint32_t height) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  for (int pass = 0; pass < r.passes; ++pass)
    for (uint32_t y = 0; y < height; ++y) png_read_row(r.png, data + y * rowBytes, nullptr);
  png_read_end(r.png, nullptr);  // through IEND: the last CRC, and a file cut after the data
  return true;
}

Image readPng(const std::string& path, FILE* f, bool srgb, uint64_t maxPixels) {
  PngRead r;
  r.file = f;
  r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, pngError, pngWarning);
  if (r.png) r.info = png_create_info_struct(r.png);
  if (!r.png || !r.info) throwDecode(path, "out of memory (libpng)");
  png_set_read_fn(r.png, &r, pngReadData);
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  // Fuzz builds only (CMakeLists.txt): a mutated PNG would almost always stop at a checksum.
  png_set_crc_action(r.png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);
  png_set_option(r.png, PNG_IGNORE_ADLER32, PNG_OPTION_ON);
#endif
  auto fail = [&]() {
    // A size that IHDR gave is reported against the limit even when a later chunk is bad.
    const uint32_t w = png_get_image_width(r.png, r.info), h = png_get_image_height(r.png, r.info);
    if (w > 0 && h > 0) checkSize(path, int(w), int(h), maxPixels);
    if (r.truncated) throwDecode(path, "truncated PNG: the file ends before the image data does");
    throwDecode(path, std::string("corrupt PNG (") + r.message + ")");
  };
  if (!pngInfo(r)) fail();
  const uint32_t w = png_get_image_width(r.png, r.info), h = png_get_image_height(r.png, r.info);
  checkSize(path, int(w), int(h), maxPixels);  // libpng caps both at 2^31 - 1
  if (!pngSetup(r)) fail();
  const int depth = png_get_bit_depth(r.png, r.info);
  const size_t rowBytes = png_get_rowbytes(r.png, r.info);
  if (png_get_channels(r.png, r.info) != 3 || (depth != 8 && depth != 16) ||
      rowBytes != size_t(w) * 3 * size_t(depth / 8))
    throwDecode(path, "PNG layout not handled (" + std::to_string(png_get_channels(r.png, r.info)) +
                          " channels of " + std::to_string(depth) + " bits after expansion)");
  std::vector<uint8_t> data(rowBytes * h);
  if (!pngPixels(r, data.data(), rowBytes, h)) fail();

  Image img(static_cast<int>(w), static_cast<int>(h));
  const auto& table = srgbTable();
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const size_t k = 3 * i + size_t(c);
      if (depth == 8) {
        img.pixels[i][c] = srgb ? table[data[k]] : float(data[k]) / 255.0f;
      } else {
        const float v = float(unsigned(data[2 * k]) << 8 | data[2 * k + 1]) / 65535.0f;
        img.pixels[i][c] = srgb ? srgbToLinear(v) : v;
      }
    }
  return img;
}

// ---- JPEG: libjpeg-turbo ----------------------------------------------------------------------

struct JpegRead {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr err{};
  jpeg_progress_mgr progress{};
  std::jmp_buf jump{};
  bool truncated = false;  // libjpeg's source reached the end of the file
  char message[JMSG_LENGTH_MAX] = "";
  // Safe whether or not jpeg_create_decompress ran or finished: it frees what cinfo.mem holds.
  ~JpegRead() { jpeg_destroy_decompress(&cinfo); }
};

// A progressive JPEG may hold any number of scans, and each one passes over the whole image:
// a small file can keep the decoder busy for hours (djpeg -maxscans guards against the same).
// Real encoders write about 10.
constexpr int kMaxJpegScans = 1000;

[[noreturn]] void jpegFail(j_common_ptr c) {
  auto* r = static_cast<JpegRead*>(c->client_data);
  (*c->err->format_message)(c, r->message);
  std::longjmp(r->jump, 1);
}
// Warnings (msg_level -1) that mean the data is corrupt are errors: libjpeg would go on and
// fill what it could not decode with grey. Those about metadata are ignored.
void jpegMessage(j_common_ptr c, int level) {
  if (level != -1) return;  // trace messages
  const int code = c->err->msg_code;
  if (code == JWRN_ADOBE_XFORM || code == JWRN_JFIF_MAJOR || code == JWRN_BOGUS_ICC) return;
  static_cast<JpegRead*>(c->client_data)->truncated = code == JWRN_JPEG_EOF;
  jpegFail(c);
}
void jpegProgress(j_common_ptr c) {
  auto* d = reinterpret_cast<j_decompress_ptr>(c);
  if (d->input_scan_number > kMaxJpegScans) {
    auto* r = static_cast<JpegRead*>(c->client_data);
    std::snprintf(r->message, sizeof r->message, "more than %d scans", kMaxJpegScans);
    std::longjmp(r->jump, 1);
  }
}

// Two steps, each returning false with r.message: the header (the size, checked by the caller
// before it allocates), then the pixels into the caller's Image.
struct JpegHeader {
  uint32_t width = 0, height = 0;
};
bool jpegHeader(JpegRead& r, FILE* f, JpegHeader& h) {
  if (setjmp(r.jump)) return false;
  jpeg_create_decompress(&r.cinfo);
  r.cinfo.progress = &r.progress;
  jpeg_stdio_src(&r.cinfo, f);
  jpeg_read_header(&r.cinfo, TRUE);
  h.width = r.cinfo.image_width;
  h.height = r.cinfo.image_height;
  // CMYK and YCCK (Adobe) come out as CMYK and are converted as stb_image did; grey and
  // YCbCr as RGB.
  const bool cmyk = r.cinfo.jpeg_color_space == JCS_CMYK || r.cinfo.jpeg_color_space == JCS_YCCK;
  r.cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_RGB;
  // libjpeg's defaults, the integer IDCT and "fancy" (triangle) chroma upsampling, are the
  // closest to stb_image of the choices (measured on the repository's JPEGs: within 3 of 255).
  r.cinfo.dct_method = JDCT_ISLOW;
  r.cinfo.do_fancy_upsampling = TRUE;
  return true;
}

// stb_image's CMYK -> RGB (stbi__blinn_8x8): channel * K / 255, rounded.
inline uint8_t blinn8(unsigned x, unsigned y) {
  unsigned t = x * y + 128;
  return uint8_t((t + (t >> 8)) >> 8);
}

bool jpegPixels(JpegRead& r, uint8_t* row, Image& img, bool srgb) {
  if (setjmp(r.jump)) return false;
  jpeg_start_decompress(&r.cinfo);
  const int n = r.cinfo.output_components;
  if ((n != 3 && n != 4) || r.cinfo.output_width != uint32_t(img.width) ||
      r.cinfo.output_height != uint32_t(img.height)) {
    std::snprintf(r.message, sizeof r.message, "unexpected output layout (%d components)", n);
    return false;
  }
  const auto& table = srgbTable();
  while (r.cinfo.output_scanline < r.cinfo.output_height) {
    const size_t y = r.cinfo.output_scanline;
    JSAMPROW rows[1] = {row};
    if (jpeg_read_scanlines(&r.cinfo, rows, 1) != 1) {
      std::snprintf(r.message, sizeof r.message, "no scanline decoded");
      return false;
    }
    Color* out = &img.pixels[y * size_t(img.width)];
    for (size_t x = 0; x < size_t(img.width); ++x) {
      const uint8_t* p = row + x * size_t(n);
      uint8_t rgb[3] = {p[0], p[1], p[2]};
      if (n == 4)
        for (int c = 0; c < 3; ++c) rgb[c] = blinn8(p[c], p[3]);
      for (int c = 0; c < 3; ++c) out[x][c] = srgb ? table[rgb[c]] : float(rgb[c]) / 255.0f;
    }
  }
  // No jpeg_finish_decompress: every row is decoded; what follows the last scan is not read.
  return true;
}

Image readJpeg(const std::string& path, FILE* f, bool srgb, uint64_t maxPixels) {
  JpegRead r;
  r.cinfo.err = jpeg_std_error(&r.err);
  r.cinfo.client_data = &r;
  r.err.error_exit = jpegFail;
  r.err.emit_message = jpegMessage;
  r.progress.progress_monitor = jpegProgress;
  auto fail = [&]() {
    if (r.truncated) throwDecode(path, "truncated JPEG: the file ends before the image data does");
    // libjpeg's messages: "Corrupt JPEG data: ...", "Unsupported JPEG process: ...", ...
    std::string msg = r.message;
    const std::string corrupt = "Corrupt JPEG data: ";
    if (msg.rfind(corrupt, 0) == 0) msg.erase(0, corrupt.size());
    if (msg.rfind("Unsupported ", 0) == 0) throwDecode(path, "JPEG feature not supported (" + msg + ")");
    throwDecode(path, "corrupt JPEG (" + msg + ")");
  };
  JpegHeader h;
  if (!jpegHeader(r, f, h)) fail();
  checkSize(path, int(h.width), int(h.height), maxPixels);  // JPEG caps both at 65535
  Image img(static_cast<int>(h.width), static_cast<int>(h.height));
  std::vector<uint8_t> row(size_t(h.width) * 4);
  if (!jpegPixels(r, row.data(), img, srgb)) fail();
  return img;
}

// stb_image 2.27 loops forever on a Radiance HDR whose run-length data has a zero count,
// which every truncated RLE file reaches (stb reads 0 past the end): found by the image fuzz
// target (data/regressions/image/hdr_rle_zero_count.hdr; CVE-2021-42715, fixed in 2.28).
// This walks the file as stbi__hdr_load does (header, resolution line, RLE scanlines),
// reading 0 past the end as stb does, and returns false when stb would not terminate.
bool hdrDecodeTerminates(const std::vector<uint8_t>& b) {
  size_t p = 0;
  auto get8 = [&]() -> int { return p < b.size() ? b[p++] : 0; };
  auto eof = [&] { return p >= b.size(); };
  auto token = [&] {  // stbi__hdr_gettoken
    std::string t;
    char c = char(get8());
    while (!eof() && c != '\n') {
      t += c;
      if (t.size() == 1023) {
        while (!eof() && get8() != '\n') {
        }
        break;
      }
      c = char(get8());
    }
    return t;
  };
  std::string magic = token();
  if (std::strcmp(magic.c_str(), "#?RADIANCE") != 0 && std::strcmp(magic.c_str(), "#?RGBE") != 0) return true;
  bool valid = false;
  for (;;) {
    std::string t = token();
    if (t.c_str()[0] == 0) break;
    if (std::strcmp(t.c_str(), "FORMAT=32-bit_rle_rgbe") == 0) valid = true;
  }
  if (!valid) return true;  // stb refuses the file
  std::string res = token();
  const char* tok = res.c_str();
  if (std::strncmp(tok, "-Y ", 3) != 0) return true;
  char* end = nullptr;
  const int height = int(std::strtol(tok + 3, &end, 10));
  tok = end;
  while (*tok == ' ') ++tok;
  if (std::strncmp(tok, "+X ", 3) != 0) return true;
  const int width = int(std::strtol(tok + 3, nullptr, 10));
  if (width < 8 || width >= 32768 || height <= 0) return true;  // flat data: a fixed amount
  for (int j = 0; j < height; ++j) {
    int c1 = get8(), c2 = get8(), len = get8();
    if (c1 != 2 || c2 != 2 || (len & 0x80)) return true;  // stb reads the rest flat
    len = (len << 8) | get8();
    if (len != width) return true;  // stb stops with an error
    for (int k = 0; k < 4; ++k) {
      int i = 0;
      while (width - i > 0) {
        int count = get8();
        if (count > 128) {  // a run
          get8();
          count -= 128;
          if (count > width - i) return true;
        } else {  // a dump
          if (count == 0) return false;
          if (count > width - i) return true;
          p += size_t(count);
        }
        i += count;
      }
    }
  }
  return true;
}

// Binary PNM (P5/P6): the header's numbers are read here first, for every such file, and
// refused above 2^31-1 (stb_image's int overflows). With 16-bit samples (maxval > 255),
// stb_image 2.27 goes wrong twice: it converts them to the requested channel count as if they were 8-bit, returning a
// buffer half the size it should be (a heap overflow when read: found by the image fuzz
// target, data/regressions/image/pnm16_channel_conversion.pgm), and it does not swap the
// big-endian samples. They are decoded here instead: value / maxval. Returns false (and
// leaves the file to stb) when the header is an 8-bit one whose samples are all there.
// stb_image's header parsing is lax: a missing number reads as 0 and the character after
// the maxval is skipped whatever it is, so "P5 8015 1" followed by a non-digit decoded as
// an 8015x1 image of uninitialised memory (compare fuzz target). A header that is not three
// decimal numbers with the maxval followed by one whitespace character is refused here.
bool readPnm16(const std::string& path, const std::vector<uint8_t>& b, bool srgb, uint64_t maxPixels,
               Image& out) {
  size_t p = 2;
  auto isSpace = [](uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; };
  auto number = [&](uint64_t& v) {
    for (;;) {  // whitespace and # comments
      while (p < b.size() && isSpace(b[p])) ++p;
      if (p < b.size() && b[p] == '#') {
        while (p < b.size() && b[p] != '\n' && b[p] != '\r') ++p;
        continue;
      }
      break;
    }
    if (p >= b.size() || b[p] < '0' || b[p] > '9') return false;
    v = 0;
    while (p < b.size() && b[p] >= '0' && b[p] <= '9') {
      v = std::min<uint64_t>(v * 10 + uint64_t(b[p] - '0'), uint64_t(1) << 40);
      ++p;
    }
    // stb_image parses the same numbers into an int, overflowing (UB; found by fuzzing).
    if (v > uint64_t(std::numeric_limits<int>::max()))
      throwDecode(path, "bad PNM header (a number larger than 2147483647)");
    return true;
  };
  uint64_t w = 0, h = 0, maxval = 0;
  if (!number(w) || !number(h) || !number(maxval))
    throwDecode(path, "bad PNM header (expected the width, height and maxval as decimal numbers)");
  if (p >= b.size() || !isSpace(b[p]))
    throwDecode(path, "bad PNM header (expected one whitespace character after the maxval)");
  if (maxval <= 255) {
    // 8-bit: stb decodes those, but reads missing samples as whatever its buffer held
    // (issue 23: a 32x32 P6 header and 100 bytes compared equal to anything dark).
    if (w > 0 && h > 0 && w <= uint64_t(1) << 24 && h <= uint64_t(1) << 24) {
      const uint64_t need = w * h * (b[1] == '5' ? 1 : 3);
      if (b.size() - (p + 1) < need)
        throwDecode(path, "truncated PNM data: " + std::to_string(b.size() - (p + 1)) + " bytes of samples, the header needs " +
                              std::to_string(need));
    }
    return false;
  }
  ++p;  // exactly one whitespace character before the samples
  if (maxval > 65535) throwDecode(path, "PNM maxval " + std::to_string(maxval) + " is more than 65535");
  if (w == 0 || h == 0) throwDecode(path, "empty image");
  if (w > uint64_t(1) << 24 || h > uint64_t(1) << 24) throwDecode(path, "image too large");
  checkSize(path, int(w), int(h), maxPixels);
  const size_t channels = b[1] == '5' ? 1 : 3;
  const size_t need = size_t(w) * size_t(h) * channels * 2;
  if (b.size() - p < need) throwDecode(path, "truncated PNM data");
  out = Image(int(w), int(h));
  for (size_t i = 0; i < out.pixels.size(); ++i)
    for (size_t c = 0; c < 3; ++c) {
      size_t k = p + 2 * (i * channels + (channels == 1 ? 0 : c));
      float v = std::min(1.0f, float((unsigned(b[k]) << 8) | b[k + 1]) / float(maxval));
      out.pixels[i][int(c)] = srgb ? srgbToLinear(v) : v;
    }
  return true;
}

uint32_t le16(const std::vector<uint8_t>& b, size_t i) { return uint32_t(b[i]) | uint32_t(b[i + 1]) << 8; }
uint32_t le32(const std::vector<uint8_t>& b, size_t i) { return le16(b, i) | le16(b, i + 2) << 16; }

// stb_image reads past the end of a BMP or TGA as zeros (or what its buffer held), so a
// truncated file decoded as a valid image (issue 23). The data length is checked against
// the header first: "" when it is long enough (or the format is not one checked here).
std::string bmpTgaTruncation(const std::vector<uint8_t>& b) {
  auto message = [](uint64_t have, uint64_t need, const char* what) {
    return std::string("truncated ") + what + " data: the file has " + std::to_string(have) +
           " bytes, the header needs " + std::to_string(need);
  };
  if (b.size() >= 2 && b[0] == 'B' && b[1] == 'M') {
    if (b.size() < 26) return "truncated BMP header";
    const uint64_t offset = le32(b, 10), dib = le32(b, 14);
    uint64_t w = 0, h = 0, bpp = 0, compression = 0;
    if (dib == 12) {
      w = le16(b, 18);
      h = le16(b, 20);
      bpp = b.size() >= 26 ? le16(b, 24) : 0;
    } else {
      if (b.size() < 34) return "truncated BMP header";
      w = uint64_t(std::abs(int64_t(int32_t(le32(b, 18)))));
      h = uint64_t(std::abs(int64_t(int32_t(le32(b, 22)))));
      bpp = le16(b, 28);
      compression = le32(b, 30);
    }
    if (compression != 0 && compression != 3) return "";  // run-length data: no fixed size
    if (w > uint64_t(1) << 24 || h > uint64_t(1) << 24) return "";  // refused by the size check
    const uint64_t need = offset + (bpp * w + 31) / 32 * 4 * h;
    return b.size() < need ? message(b.size(), need, "BMP") : "";
  }
  // TGA has no magic number: the header fields stb_image accepts, where no other format matched.
  if (b.size() < 18) return "";
  const unsigned cmapType = b[1], type = b[2], bpp = b[16];
  const bool rle = type == 9 || type == 10 || type == 11;
  if (cmapType > 1 || !((type >= 1 && type <= 3) || rle)) return "";
  const uint64_t w = le16(b, 12), h = le16(b, 14);
  if (w == 0 || h == 0 || bpp == 0) return "";
  const uint64_t entryBytes = (uint64_t(b[7]) + 7) / 8;
  const uint64_t pixelBytes = (uint64_t(bpp) + 7) / 8;
  uint64_t p = 18 + uint64_t(b[0]) + (cmapType ? uint64_t(le16(b, 5)) * entryBytes : 0);
  if (!rle) {
    const uint64_t need = p + w * h * pixelBytes;
    return b.size() < need ? message(b.size(), need, "TGA") : "";
  }
  // Run-length packets: a count byte, then one pixel (a run) or count pixels (raw).
  for (uint64_t done = 0; done < w * h;) {
    if (p >= b.size()) return "truncated TGA data: the run-length packets end before the last pixel";
    const unsigned c = b[p++];
    const uint64_t n = (c & 0x7f) + 1;
    p += (c & 0x80 ? 1 : n) * pixelBytes;
    done += n;
  }
  return p > b.size() ? "truncated TGA data: the run-length packets end before the last pixel" : "";
}

struct StbiFree {
  void operator()(void* p) const { stbi_image_free(p); }
};
struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};

}  // namespace

float srgbToLinear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

uint8_t quantize8(float v, ToneMap tonemap, float scale) {
  if (std::isnan(v)) return 0;
  v *= scale;
  if (tonemap == ToneMap::Filmic) {
    // Narkowicz 2015, "ACES Filmic Tone Mapping Curve", with his 0.6 pre-scale.
    float x = std::max(0.0f, v) * 0.6f;
    if (std::isinf(x)) return 255;
    v = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
  }
  v = std::clamp(v, 0.0f, 1.0f);
  if (tonemap != ToneMap::Clamp) v = linearToSrgb(v);
  return uint8_t(std::lround(v * 255.0f));
}

bool isWritableImageExtension(const std::string& ext) {
  std::string e = normalizeExt(ext);
  return e == "png" || e == "ppm" || e == "bmp" || e == "exr";
}

void writeImage(const std::string& path, const Image& image, const WriteOptions& options) {
  const std::string ext = fileExtension(path);
  if (!isWritableImageExtension(ext)) {
    if (ext.empty()) throw Error("cannot write " + quoteInput(path) + ": no image format extension " + kFormatsHint);
    // Report the extension as the user spelled it.
    std::string given = std::filesystem::path(path).extension().string();
    throw Error("cannot write " + quoteInput(path) + ": unknown image format " + quoteInput(given) + " " + kFormatsHint);
  }
  if (image.width <= 0 || image.height <= 0)
    throw Error("cannot write " + quoteInput(path) + ": empty image (" + std::to_string(image.width) + "x" +
                std::to_string(image.height) + ")");
  if (image.pixels.size() != size_t(image.width) * size_t(image.height))
    throw Error("cannot write " + quoteInput(path) + ": pixel count does not match " +
                std::to_string(image.width) + "x" + std::to_string(image.height));

  for (const WriteOptions::Channel& c : options.channels) {
    if (ext != "exr")
      throw Error("cannot write " + quoteInput(path) + ": channel '" + c.name + "' needs an .exr output");
    if (c.values.size() != image.pixels.size())
      throw Error("cannot write " + quoteInput(path) + ": channel '" + c.name + "' does not match the image size");
    if (c.name.empty() || c.name == "R" || c.name == "G" || c.name == "B")
      throw Error("cannot write " + quoteInput(path) + ": bad channel name '" + c.name + "'");
  }
  if (ext == "exr") {
    writeFileAtomically(path,
                        [&](const std::string& tmp) { writeExr(tmp, path, image, options.metadata, options.channels, options.threads); });
    return;
  }
  // Encode in memory first so that file errors come from our own writes (with errno)
  // rather than from stb's silent 0 return.
  std::vector<uint8_t> rgb = toBytes(image, options.tonemap, options.exposure);
  std::vector<uint8_t> encoded;
  if (ext == "ppm") {
    encoded = encodePpm(image, rgb);
  } else {
    int ok = ext == "png" ? stbi_write_png_to_func(appendToVector, &encoded, image.width, image.height, 3,
                                                   rgb.data(), image.width * 3)
                          : stbi_write_bmp_to_func(appendToVector, &encoded, image.width, image.height, 3,
                                                   rgb.data());
    if (!ok) throw Error("cannot write " + quoteInput(path) + ": the " + ext + " encoder failed");
    if (ext == "png" && !options.metadata.empty()) encoded = addPngText(encoded, options.metadata);
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

  // Formats outside the documented set are refused before stb_image: less decoder to trust.
  if (got >= 4 && std::memcmp(magic, "GIF8", 4) == 0) throwDecode(path, "GIF images are not supported");
  if (got >= 4 && std::memcmp(magic, "8BPS", 4) == 0) throwDecode(path, "PSD images are not supported");
  if (got >= 4 && magic[0] == 0x53 && magic[1] == 0x80 && magic[2] == 0xF6 && magic[3] == 0x34)
    throwDecode(path, "PIC images are not supported");
  // PNG and JPEG go to libpng and libjpeg-turbo. A file that starts with FF is a JPEG unless
  // its second byte is a TGA colour-map type (0 or 1: a TGA whose ID field is 255 bytes long).
  if (got == 4 && magic[0] == 0x89 && magic[1] == 'P' && magic[2] == 'N' && magic[3] == 'G')
    return readPng(path, f.get(), srgb, maxPixels);
  if (got >= 2 && magic[0] == 0xFF && magic[1] > 1) return readJpeg(path, f.get(), srgb, maxPixels);

  if (got >= 2 && magic[0] == 'P' && (magic[1] == '5' || magic[1] == '6')) {
    Image img;
    if (readPnm16(path, readAll(f.get()), srgb, maxPixels, img)) return img;
  }

  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_file(f.get(), &w, &h, &comp)) throwDecode(path, stbiReason());
  // stbi_info reports a top-down BMP's height as negative (as stored); the decoder flips it.
  if (h < 0 && h != std::numeric_limits<int>::min()) h = -h;
  checkSize(path, w, h, maxPixels);
  // PNM and HDR are checked elsewhere (by stb itself or above); BMP and TGA here.
  if (!(got >= 1 && (magic[0] == 'P' || magic[0] == '#'))) {
    std::string why = bmpTgaTruncation(readAll(f.get()));
    if (!why.empty()) throwDecode(path, why);
  }

  // Ask for 3 channels: stb expands grey and drops alpha.
  if (stbi_is_hdr_from_file(f.get())) {
    if (!hdrDecodeTerminates(readAll(f.get()))) throwDecode(path, "corrupt HDR (bad run-length data)");
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
