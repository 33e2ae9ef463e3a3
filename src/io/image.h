// Float RGB images and their file formats. 8-bit outputs (PNG, PPM, BMP) clamp linear
// values to [0,1] as the course renderer did (or apply the sRGB curve with srgb = true);
// EXR keeps linear floats. Every write is atomic (temporary file, then rename).
#pragma once

#include <string>
#include <vector>

#include "core/math.h"

namespace lc::io {

struct Image {
  int width = 0, height = 0;
  std::vector<Color> pixels;  // row-major, top row first

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h)) {}
  Color& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const Color& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

enum class ToneMap { Clamp, Srgb };

// Writes by extension: .png .ppm .bmp (8-bit) or .exr (float). Throws lc::Error
// (unknown extension, unwritable path) and leaves any existing file untouched on failure.
void writeImage(const std::string& path, const Image& image, ToneMap tonemap = ToneMap::Clamp);

// Reads .exr as linear floats, and 8-bit formats (.png .jpg .bmp .tga .ppm .hdr) via stb_image:
// 8-bit values become value/255 (linearised when srgb = true); .hdr stays linear.
Image readImage(const std::string& path, bool srgb = false);

// True for extensions writeImage accepts.
bool isWritableImageExtension(const std::string& ext);

}  // namespace lc::io
