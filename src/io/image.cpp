#include "io/image.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/file_util.h"
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
              const std::vector<WriteOptions::Channel>& channels) {
  // NaN -> 0 as in the 8-bit formats; infinities are kept (EXR can hold them).
  std::vector<Color> px(img.pixels);
  for (Color& c : px)
    for (int k = 0; k < 3; ++k)
      if (std::isnan(c[k])) c[k] = 0;
  try {
    Imf::Header header(img.width, img.height);
    // 32-bit float channels: the round trip is exact (half would lose precision).
    for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
    for (const WriteOptions::Channel& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(Color), ys = sizeof(Color) * size_t(img.width);
    char* base = reinterpret_cast<char*>(px.data());
    fb.insert("R", Imf::Slice(Imf::FLOAT, base + offsetof(Color, x), xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + offsetof(Color, y), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + offsetof(Color, z), xs, ys));
    for (const WriteOptions::Channel& c : channels)
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.values.data())),
                                   sizeof(float), sizeof(float) * size_t(img.width)));
    Imf::OutputFile file(tmp.c_str(), header);
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

// JPEG files are checked before stb_image 2.27 (Debian's libstb) sees them, for two bugs
// the image fuzz target found (data/regressions/image/jpeg_*):
//  - a Huffman table (DHT) whose code counts add up to more than 256 makes it write past
//    stbi__huffman::size[257]; one with 256 codes of at most 9 bits makes the slow decode
//    path index values[] with a negative symbol id;
//  - a scan (SOS) that uses a Huffman table no DHT defined makes it decode with
//    uninitialised memory (it mallocs its state without clearing it): reads far out of
//    bounds.
// The walk follows stb's own (stbi__decode_jpeg_header, stbi__decode_jpeg_image): fill
// bytes, junk between segments before the frame header, 0 read past the end. Entropy-coded
// data is skipped to the next FF xx that is not a stuffed 00, a fill FF or a restart
// marker: stb either stops at that same marker or ends the image earlier, so every DHT and
// SOS it acts on is one the walk checks. Returns the reason to refuse the file, or "".
// Besides the walk, every FF C4 in the file is checked as a DHT (cheap, and independent of
// the walk's reading of the structure).
std::string jpegProblem(const std::vector<uint8_t>& b) {
  auto tableProblem = [](const int* counts) -> const char* {
    int n = 0, short9 = 0;
    for (int i = 0; i < 16; ++i) {
      n += counts[i];
      if (i < 9) short9 += counts[i];
    }
    if (n > 256) return "corrupt JPEG (a Huffman table has more than 256 codes)";
    if (n == 256 && short9 == 256) return "corrupt JPEG (a Huffman table has 256 codes of at most 9 bits)";
    return nullptr;
  };
  for (size_t i = 0; i + 1 < b.size(); ++i) {
    if (b[i] != 0xFF || b[i + 1] != 0xC4) continue;
    size_t q = i + 2;
    auto at = [&](size_t k) -> int { return k < b.size() ? b[k] : 0; };
    long len = (at(q) << 8) + at(q + 1) - 2;
    q += 2;
    while (len > 0 && q < b.size()) {
      if ((at(q) >> 4) > 1 || (at(q) & 15) > 3) break;
      int counts[16], n = 0;
      for (int k = 0; k < 16; ++k) n += counts[k] = at(q + 1 + size_t(k));
      if (const char* why = tableProblem(counts)) return why;
      q += 17 + size_t(n);
      len -= 17 + n;
    }
  }

  size_t p = 0;
  auto eof = [&] { return p >= b.size(); };
  auto get8 = [&]() -> int { return p < b.size() ? b[p++] : 0; };
  auto get16 = [&] {
    int hi = get8();
    return (hi << 8) + get8();
  };
  auto skip = [&](long n) { p = n > 0 ? std::min(b.size(), p + size_t(n)) : p; };
  constexpr int kNone = 0xFF;
  auto marker = [&]() -> int {  // stbi__get_marker
    int x = get8();
    if (x != 0xFF) return kNone;
    while (x == 0xFF) x = get8();
    return x;
  };
  bool dcDefined[4] = {false, false, false, false}, acDefined[4] = {false, false, false, false};
  std::string problem;
  // stbi__process_marker: false when stb fails (the image ends there).
  auto processMarker = [&](int m) -> bool {
    if (m == 0xDD) {  // DRI
      if (get16() != 4) return false;
      get16();
      return true;
    }
    if (m == 0xDB) {  // DQT
      long len = get16() - 2;
      while (len > 0) {
        int q = get8(), pq = q >> 4, t = q & 15;
        if ((pq != 0 && pq != 1) || t > 3) return false;
        skip(pq ? 128 : 64);
        len -= pq ? 129 : 65;
      }
      return len == 0;
    }
    if (m == 0xC4) {  // DHT
      long len = get16() - 2;
      while (len > 0) {
        int q = get8(), tc = q >> 4, th = q & 15;
        if (tc > 1 || th > 3) return false;
        int counts[16], n = 0;
        for (int k = 0; k < 16; ++k) n += counts[k] = get8();
        if (const char* why = tableProblem(counts)) {
          problem = why;
          return false;
        }
        (tc == 0 ? dcDefined : acDefined)[th] = true;
        skip(n);
        len -= 17 + n;
      }
      return len == 0;
    }
    if ((m >= 0xE0 && m <= 0xEF) || m == 0xFE) {  // APPn, COM
      int len = get16();
      if (len < 2) return false;
      skip(len - 2);
      return true;
    }
    return false;
  };

  if (marker() != 0xD8) return "";  // not a JPEG to stb
  int m = marker();
  while (!(m == 0xC0 || m == 0xC1 || m == 0xC2)) {
    if (!processMarker(m)) return problem;
    m = marker();
    while (m == kNone) {
      if (eof()) return problem;
      m = marker();
    }
  }
  const bool progressive = m == 0xC2;
  // Frame header (stbi__process_frame_header): the component ids.
  int lf = get16();
  get8();
  get16();
  get16();
  int nComp = get8();
  if (nComp != 1 && nComp != 3 && nComp != 4) return problem;
  if (lf != 8 + 3 * nComp) return problem;
  int ids[4];
  for (int i = 0; i < nComp; ++i) {
    ids[i] = get8();
    get8();
    get8();
  }
  m = marker();
  while (m != 0xD9) {
    if (m == 0xDA) {  // SOS (stbi__process_scan_header)
      int ls = get16(), nScan = get8();
      if (nScan < 1 || nScan > 4 || nScan > nComp || ls != 6 + 2 * nScan) return problem;
      int hd[4], ha[4];
      for (int i = 0; i < nScan; ++i) {
        int id = get8(), q = get8(), which = 0;
        while (which < nComp && ids[which] != id) ++which;
        if (which == nComp) return problem;
        hd[i] = q >> 4;
        ha[i] = q & 15;
        if (hd[i] > 3 || ha[i] > 3) return problem;
      }
      int specStart = get8(), specEnd = get8(), aa = get8(), succHigh = aa >> 4, succLow = aa & 15;
      if (progressive) {
        if (specStart > 63 || specEnd > 63 || specStart > specEnd || succHigh > 13 || succLow > 13) return problem;
      } else if (specStart != 0 || succHigh != 0 || succLow != 0) {
        return problem;
      }
      for (int i = 0; i < nScan; ++i) {
        bool needDc = progressive ? specStart == 0 && succHigh == 0 : true;
        bool needAc = progressive ? specStart != 0 : true;
        if ((needDc && !dcDefined[hd[i]]) || (needAc && !acDefined[ha[i]]))
          return "corrupt JPEG (a scan uses a Huffman table that is not defined)";
      }
      // Entropy-coded data: to the next FF xx that is a marker.
      m = -1;
      while (p < b.size() && m < 0) {
        if (b[p++] != 0xFF) continue;
        int x = get8();
        while (x == 0xFF) x = get8();
        if (x != 0 && !(x >= 0xD0 && x <= 0xD7)) m = x;
      }
      if (m < 0) return problem;  // end of file
      continue;
    }
    if (m == 0xDC) {  // DNL
      if (get16() != 4) return problem;
      get16();
    } else if (!processMarker(m)) {
      return problem;
    }
    m = marker();
  }
  return problem;
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

// Binary PNM with 16-bit samples (P5/P6, maxval > 255). stb_image 2.27 gets these wrong
// twice: it converts them to the requested channel count as if they were 8-bit, returning a
// buffer half the size it should be (a heap overflow when read: found by the image fuzz
// target, data/regressions/image/pnm16_channel_conversion.pgm), and it does not swap the
// big-endian samples. They are decoded here instead: value / maxval. Returns false (and
// leaves the file to stb) when the header is not a 16-bit binary PNM header.
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
    return true;
  };
  uint64_t w = 0, h = 0, maxval = 0;
  if (!number(w) || !number(h) || !number(maxval)) return false;
  if (maxval <= 255) {
    // 8-bit: stb decodes those, but reads missing samples as whatever its buffer held
    // (issue 23: a 32x32 P6 header and 100 bytes compared equal to anything dark).
    if (p < b.size() && isSpace(b[p]) && w > 0 && h > 0 && w <= uint64_t(1) << 24 && h <= uint64_t(1) << 24) {
      const uint64_t need = w * h * (b[1] == '5' ? 1 : 3);
      if (b.size() - (p + 1) < need)
        throwDecode(path, "truncated PNM data: " + std::to_string(b.size() - (p + 1)) + " bytes of samples, the header needs " +
                              std::to_string(need));
    }
    return false;
  }
  if (p >= b.size() || !isSpace(b[p])) throwDecode(path, "bad PNM header");
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

ToneMap parseToneMap(const std::string& name) {
  if (name == "clamp") return ToneMap::Clamp;
  if (name == "srgb") return ToneMap::Srgb;
  if (name == "filmic") return ToneMap::Filmic;
  throw Error("unknown tone map " + quoteInput(name) + " (use clamp, srgb or filmic)");
}

const char* toneMapName(ToneMap tonemap) {
  switch (tonemap) {
    case ToneMap::Clamp: return "clamp";
    case ToneMap::Srgb: return "srgb";
    case ToneMap::Filmic: return "filmic";
  }
  return "clamp";
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
                        [&](const std::string& tmp) { writeExr(tmp, path, image, options.metadata, options.channels); });
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
  // stb takes FF (FF)* D8 as a JPEG start: any file that starts with FF is checked.
  if (got >= 1 && magic[0] == 0xFF) {
    std::string why = jpegProblem(readAll(f.get()));
    if (!why.empty()) throwDecode(path, why);
  }

  if (got >= 2 && magic[0] == 'P' && (magic[1] == '5' || magic[1] == '6')) {
    Image img;
    if (readPnm16(path, readAll(f.get()), srgb, maxPixels, img)) return img;
  }

  // A PNG's size comes from its IHDR, read here: stb refuses sizes over 2^24 with a reason
  // that stbi_info loses ("unknown image type"), and the limit is the one to report.
  if (got == 4 && magic[0] == 0x89 && magic[1] == 'P' && magic[2] == 'N' && magic[3] == 'G') {
    unsigned char head[24];
    if (std::fread(head, 1, sizeof head, f.get()) == sizeof head &&
        std::memcmp(head + 12, "IHDR", 4) == 0) {
      auto be32 = [&](int at) {
        return uint32_t(head[at]) << 24 | uint32_t(head[at + 1]) << 16 | uint32_t(head[at + 2]) << 8 |
               uint32_t(head[at + 3]);
      };
      uint32_t pw = be32(16), ph = be32(20);
      // The PNG specification caps both at 2^31 - 1; larger is a corrupt header.
      const uint32_t kMaxInt = uint32_t(std::numeric_limits<int>::max());
      if (pw > kMaxInt || ph > kMaxInt) throwDecode(path, "corrupt PNG (bad IHDR size)");
      checkSize(path, int(pw), int(ph), maxPixels);
      // stb_image's own cap (STBI_MAX_DIMENSIONS, 2^24 per side by default).
      if (pw > (1u << 24) || ph > (1u << 24))
        throwDecode(path, std::to_string(pw) + "x" + std::to_string(ph) +
                              " PNG is wider or taller than the decoder's 16777216 pixels");
    }
    std::rewind(f.get());
  }

  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_file(f.get(), &w, &h, &comp)) throwDecode(path, stbiReason());
  // stbi_info reports a top-down BMP's height as negative (as stored); the decoder flips it.
  if (h < 0 && h != std::numeric_limits<int>::min()) h = -h;
  checkSize(path, w, h, maxPixels);
  // PNG, JPEG, PNM and HDR are checked elsewhere (by stb itself or above); BMP and TGA here.
  if (!(got >= 1 && (magic[0] == 0x89 || magic[0] == 0xFF || magic[0] == 'P' || magic[0] == '#'))) {
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
