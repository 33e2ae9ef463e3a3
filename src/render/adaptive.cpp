#include "render/adaptive.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace lc::render {

const char* antiAliasingName(AntiAliasing aa) { return aa == AntiAliasing::Adaptive ? "adaptive" : "off"; }

AntiAliasing parseAntiAliasing(const std::string& name) {
  if (name == "adaptive") return AntiAliasing::Adaptive;
  if (name == "off") return AntiAliasing::Off;
  throw Error("unknown antialiasing '" + name + "' (use adaptive or off)");
}

bool disagree(const CentreSample& a, const CentreSample& b, const RenderOptions& o) {
  if (a.shape == -2 || b.shape == -2) return false;  // outside the image
  if (a.shape != b.shape) return true;
  if (a.shape >= 0 && dot(a.n, b.n) < o.aaNormalCos) return true;
  if (a.known && b.known) {  // as displayed: white is white however bright
    const float la = std::min(a.luminance, 1.0f), lb = std::min(b.luminance, 1.0f);
    const float hi = std::max({la, lb, o.aaContrastFloor});
    if (std::fabs(la - lb) > o.aaContrast * hi) return true;
  }
  return false;
}

std::vector<uint8_t> flagPixels(const std::vector<CentreSample>& ring, int w, int h, const RenderOptions& o) {
  std::vector<uint8_t> flags(size_t(w) * size_t(h), 0);
  const int rw = w + 2;
  auto at = [&](int x, int y) -> const CentreSample& { return ring[size_t(y + 1) * size_t(rw) + size_t(x + 1)]; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const CentreSample& c = at(x, y);
      bool f = false;
      for (int dy = -1; dy <= 1 && !f; ++dy)
        for (int dx = -1; dx <= 1 && !f; ++dx)
          if (dx || dy) f = disagree(c, at(x + dx, y + dy), o);
      flags[size_t(y) * size_t(w) + size_t(x)] = f;
    }
  return flags;
}

int aaGridSide(int aaSamples) {
  for (int g = 3; g <= 15; g += 2)
    if (g * g - 1 == aaSamples) return g;
  return 0;
}

Vec2 aaSubSamplePosition(int s, int g, Rng& rng) {
  const int middle = (g * g) / 2;
  int k = s < middle ? s : s + 1;
  int ix = k % g, iy = k / g;
  float jx = rng.uniform(), jy = rng.uniform();
  return Vec2((float(ix) + jx) / float(g), (float(iy) + jy) / float(g));
}

}  // namespace lc::render
