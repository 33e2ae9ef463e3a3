// Image textures: bilinear lookups with REPEAT wrapping, and a cache that decodes each
// file once per scene.
//
// Texture coordinates follow the OpenGL/OBJ convention: u runs left to right, v runs
// BOTTOM to TOP (v = 0 is the bottom row of the image file, v = 1 its top). Texel (i, j),
// counted from the left and from the bottom, has its centre at ((i+0.5)/w, (j+0.5)/h).
// Any real u, v is valid: both wrap with period 1 (so u = 0 blends the last and first
// columns half and half). Values are whatever the image held (linear floats).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/limits.h"
#include "core/math.h"
#include "io/image.h"
#include "io/scene_desc.h"

namespace lc::scene {

class Texture {
 public:
  // Decodes `path` (any format io::readImage reads; `srgb` linearises 8-bit values).
  // Throws lc::Error "cannot open texture 'path': reason", "cannot read texture 'path':
  // reason" or "texture 'path' is WxH = N pixels, more than --max-texture-pixels (M)".
  static std::shared_ptr<const Texture> load(const std::string& path, bool srgb, const Limits& limits);

  // Takes an image (top row first, as io::Image stores it). An empty image becomes a
  // single black texel so that lookups never divide by zero.
  explicit Texture(io::Image img);

  // Bilinearly filtered colour at uv (wrapping; v up). Non-finite u or v read as 0.
  Color lookup(Vec2 uv) const;
  // The mean of the three channels of lookup(uv): scalar maps (shininess, index).
  float lookupScalar(Vec2 uv) const;

  int width() const { return img_.width; }
  int height() const { return img_.height; }
  // The mean texel (e.g. the average emission of a textured light).
  Color average() const { return average_; }
  // Texel (i, j) with j counted from the BOTTOM row, matching uv; no wrapping.
  const Color& texel(int i, int j) const { return img_.at(i, img_.height - 1 - j); }

 private:
  io::Image img_;
  Color average_;
};

// Decodes each (path, srgb) once and hands out the shared texture. Thread-safe.
class TextureCache {
 public:
  // Throws lc::Error at ref.loc naming the file, e.g.
  // "scene.ray:12:15: error: cannot open texture 'checker.bmp': No such file or directory".
  std::shared_ptr<const Texture> get(const io::TextureRef& ref, const Limits& limits);
  size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, bool>, std::shared_ptr<const Texture>> textures_;
};

}  // namespace lc::scene
