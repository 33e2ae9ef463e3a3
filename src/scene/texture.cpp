#include "scene/texture.h"

#include <cmath>
#include <filesystem>

#include "core/error.h"

namespace lc::scene {

namespace {

int wrapIndex(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

}  // namespace

std::shared_ptr<const Texture> Texture::load(const std::string& path, bool srgb, const Limits& limits) {
  try {
    return std::make_shared<const Texture>(io::readImage(path, srgb, limits.maxTexturePixels));
  } catch (const io::ImageReadError& e) {
    // Reword readImage's messages so the user sees that a texture was being read.
    switch (e.kind) {
      case io::ImageReadError::Kind::Open:
        throw Error("cannot open texture " + quoteInput(path) + ": " + e.reason);
      case io::ImageReadError::Kind::TooLarge:
        throw Error("texture " + quoteInput(path) + " is " + std::to_string(e.width) + "x" +
                    std::to_string(e.height) + " = " +
                    std::to_string(uint64_t(e.width) * uint64_t(e.height)) +
                    " pixels, more than --max-texture-pixels (" +
                    std::to_string(limits.maxTexturePixels) + ")");
      case io::ImageReadError::Kind::Memory:
        throw Error(e.reason);
      case io::ImageReadError::Kind::Decode:
        break;
    }
    throw Error("cannot read texture " + quoteInput(path) + ": " + e.reason);
  }
}

Texture::Texture(io::Image img) : img_(std::move(img)) {
  if (img_.width <= 0 || img_.height <= 0 ||
      img_.pixels.size() != size_t(img_.width) * size_t(img_.height))
    img_ = io::Image(1, 1);
  // Sum in double: a 16k x 16k texture would lose the small texels in float.
  double s[3] = {0, 0, 0};
  for (const Color& c : img_.pixels)
    for (int k = 0; k < 3; ++k) s[k] += double(c[k]);
  double n = double(img_.pixels.size());
  average_ = Color(float(s[0] / n), float(s[1] / n), float(s[2] / n));
}

Color Texture::lookup(Vec2 uv) const {
  const int w = img_.width, h = img_.height;
  float u = std::isfinite(uv.x) ? uv.x : 0.0f;
  float v = std::isfinite(uv.y) ? uv.y : 0.0f;
  // Reduce to [0,1] first so huge coordinates cannot overflow the int conversion.
  u -= std::floor(u);
  v -= std::floor(v);
  // Continuous texel coordinates with texel centres on integers; rows counted from the
  // top as the image stores them, hence 1 - v.
  float x = u * float(w) - 0.5f;
  float y = (1.0f - v) * float(h) - 0.5f;
  float x0f = std::floor(x), y0f = std::floor(y);
  float fx = x - x0f, fy = y - y0f;
  int x0 = wrapIndex(int(x0f), w), x1 = wrapIndex(int(x0f) + 1, w);
  int y0 = wrapIndex(int(y0f), h), y1 = wrapIndex(int(y0f) + 1, h);
  Color top = lerp(fx, img_.at(x0, y0), img_.at(x1, y0));
  Color bottom = lerp(fx, img_.at(x0, y1), img_.at(x1, y1));
  return lerp(fy, top, bottom);
}

float Texture::lookupScalar(Vec2 uv) const {
  Color c = lookup(uv);
  return (c.x + c.y + c.z) / 3.0f;
}

std::shared_ptr<const Texture> TextureCache::get(const io::TextureRef& ref, const Limits& limits) {
  // Key on the canonical path so "a/../t.png" and "t.png" share one decode.
  std::error_code ec;
  std::string key = std::filesystem::weakly_canonical(ref.path, ec).string();
  if (ec || key.empty()) key = ref.path;

  // One lock around the decode too: simple, and a second thread asking for the same
  // file waits for it rather than decoding it again.
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = textures_.find({key, ref.srgb});
  if (it != textures_.end()) return it->second;
  std::shared_ptr<const Texture> tex;
  try {
    tex = Texture::load(ref.path, ref.srgb, limits);
  } catch (const Error& e) {
    throw Error(ref.loc, e.bare());
  }
  textures_.emplace(std::make_pair(key, ref.srgb), tex);
  return tex;
}

size_t TextureCache::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return textures_.size();
}

}  // namespace lc::scene
