// Text metadata in PNG files: stb_image_write has no place for it, so the chunks are
// inserted into the stream it produced (right after IHDR) and read back by walking the
// chunks. tEXt for ASCII values, uncompressed iTXt (UTF-8) otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lc::io {

using TextMetadata = std::vector<std::pair<std::string, std::string>>;

// CRC-32 as PNG (and zlib) define it: polynomial 0xEDB88320, initial and final XOR ~0.
uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

// `png` with one text chunk per (keyword, text) after its IHDR chunk. Throws lc::Error when
// `png` does not start with a PNG signature and IHDR, or a keyword is not 1..79 printable
// ASCII characters (PNG's rule; leading, trailing and double spaces are not allowed either),
// or a value holds a NUL byte.
std::vector<uint8_t> addPngText(const std::vector<uint8_t>& png, const TextMetadata& text);

// The tEXt and uncompressed iTXt chunks of a PNG stream, in file order; chunks whose CRC
// does not match are left out. Empty for anything that is not a PNG.
TextMetadata readPngText(const std::vector<uint8_t>& png);

}  // namespace lc::io
