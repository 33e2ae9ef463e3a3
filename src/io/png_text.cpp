#include "io/png_text.h"

#include <array>
#include <cstring>

#include "core/error.h"

namespace lc::io {

namespace {

constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

uint32_t readBe32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}
void appendBe32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

bool isAscii(const std::string& s) {
  for (unsigned char c : s)
    if (c >= 0x80) return false;
  return true;
}

void checkKeyword(const std::string& k) {
  bool ok = !k.empty() && k.size() <= 79 && k.front() != ' ' && k.back() != ' ' && k.find("  ") == std::string::npos;
  for (unsigned char c : k) ok = ok && c >= 0x20 && c < 0x7f;
  if (!ok) throw Error("PNG text keyword " + quoteInput(k) + " is not 1 to 79 printable ASCII characters");
}

void appendChunk(std::vector<uint8_t>& out, const char type[4], const std::vector<uint8_t>& data) {
  appendBe32(out, uint32_t(data.size()));
  size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  appendBe32(out, crc32(out.data() + start, out.size() - start));
}

}  // namespace

uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xff] ^ (crc >> 8);
  return ~crc;
}

std::vector<uint8_t> addPngText(const std::vector<uint8_t>& png, const TextMetadata& text) {
  // Signature (8) + IHDR chunk (4 length + 4 type + 13 data + 4 CRC).
  constexpr size_t kIhdrEnd = 8 + 4 + 4 + 13 + 4;
  if (png.size() < kIhdrEnd || std::memcmp(png.data(), kSignature, 8) != 0 ||
      std::memcmp(png.data() + 12, "IHDR", 4) != 0 || readBe32(png.data() + 8) != 13)
    throw Error("addPngText: not a PNG stream starting with IHDR");
  std::vector<uint8_t> out(png.begin(), png.begin() + kIhdrEnd);
  for (const auto& [key, value] : text) {
    checkKeyword(key);
    if (value.find('\0') != std::string::npos)
      throw Error("PNG text " + quoteInput(key) + " holds a NUL character");
    std::vector<uint8_t> data(key.begin(), key.end());
    data.push_back(0);
    if (isAscii(value)) {
      data.insert(data.end(), value.begin(), value.end());
      appendChunk(out, "tEXt", data);
    } else {
      // iTXt: keyword, NUL, compression flag 0, method 0, empty language tag and translated
      // keyword (each NUL-terminated), then the UTF-8 text.
      for (uint8_t b : {0, 0, 0, 0}) data.push_back(b);
      data.insert(data.end(), value.begin(), value.end());
      appendChunk(out, "iTXt", data);
    }
  }
  out.insert(out.end(), png.begin() + kIhdrEnd, png.end());
  return out;
}

TextMetadata readPngText(const std::vector<uint8_t>& png) {
  TextMetadata out;
  if (png.size() < 8 || std::memcmp(png.data(), kSignature, 8) != 0) return out;
  size_t at = 8;
  while (png.size() - at >= 12) {
    uint32_t len = readBe32(png.data() + at);
    if (len > png.size() - at - 12) break;
    const uint8_t* type = png.data() + at + 4;
    const uint8_t* data = type + 4;
    bool crcOk = crc32(type, size_t(len) + 4) == readBe32(data + len);
    std::string body(reinterpret_cast<const char*>(data), len);
    size_t nul = body.find('\0');
    if (crcOk && nul != std::string::npos) {
      std::string key = body.substr(0, nul);
      if (std::memcmp(type, "tEXt", 4) == 0) {
        out.emplace_back(key, body.substr(nul + 1));
      } else if (std::memcmp(type, "iTXt", 4) == 0 && body.size() >= nul + 3 && body[nul + 1] == 0) {
        // Skip the flags, then the language tag and the translated keyword.
        size_t lang = body.find('\0', nul + 3);
        size_t trans = lang == std::string::npos ? lang : body.find('\0', lang + 1);
        if (trans != std::string::npos) out.emplace_back(key, body.substr(trans + 1));
      }
    }
    if (std::memcmp(type, "IEND", 4) == 0) break;
    at += size_t(len) + 12;
  }
  return out;
}

}  // namespace lc::io
