#include "render/adaptive.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "render/reconstruction_tiles.h"

namespace lc::render {

std::string antiAliasingHelp(const RenderOptions& o) {
  return fmt::format(fmt::runtime(enumHelp(kAntiAliasingNames)),
                     fmt::arg("normal_degrees", std::acos(o.aaNormalCos) * 180 / kPi),
                     fmt::arg("contrast_percent", 100 * o.aaContrast));
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

namespace {

// What a pixel's sub-samples add: their radiance, cut nodes and shadow rays, summed.
struct SubSampleSums {
  Color color{0};
  double cut = 0, shadowRays = 0;
  int count = 0;
  uint64_t fallbacks = 0;  // sub-samples no reconstruction sample could serve
};

// The sub-samples of pixel (x, y) on the g x g grid; under reconstruction cuts (rt) each
// borrows from the tile's samples (ReconstructionTile::subSampleHook).
SubSampleSums traceSubSamples(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                              int x, int y, int g, lightcuts::EvalStats& stats, uint64_t& primary,
                              uint64_t& secondary, const ReconstructionTile* rt, AaCutCache* cache) {
  SubSampleSums sums;
  Rng rng(o.seed, aaStream(x, y, o.width, o.height));
  const scene::Camera& cam = scene.camera();
  for (int s = 0; s < g * g - 1; ++s) {
    Vec2 u = aaSubSamplePosition(s, g, rng);
    scene::Ray ray{cam.eye,
                   normalize(cam.direction((float(x) + u.x) / float(o.width), (float(y) + u.y) / float(o.height))), 0,
                   kInf};
    PrimaryHook hook;
    const CutSample* chosen[4];
    if (rt) rt->subSampleHook(ray, x, y, u, hook, chosen, *cache);
    Tracer tr{scene, ev, o.maxDepth, stats, rt ? &hook : nullptr};
    const uint64_t rays0 = stats.shadowRays;
    ++primary;
    Color c = tr.trace(ray, 0);
    if (!isFinite(c)) c = Color(0);
    sums.color += c;
    sums.cut += double(tr.cutNodes);
    sums.shadowRays += double(stats.shadowRays - rays0);
    secondary += tr.secondaryRays;
    sums.fallbacks += hook.fallbacks;
    ++sums.count;
  }
  return sums;
}

}  // namespace

void adaptiveTile(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                  RenderResult& res, TileCounters& counters, const TileRect& rect, const ReconstructionTile* rt,
                  AaCutCache* cache) {
  if (o.aa != AntiAliasing::Adaptive || o.spp != 1) return;
  const int g = aaGridSide(o.aaSamples);
  if (g == 0) return;
  if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
  const int x0 = rect.x0, y0 = rect.y0, x1 = rect.x1, y1 = rect.y1;
  const int w = x1 - x0, h = y1 - y0;
  std::vector<CentreSample> ring(size_t(w + 2) * size_t(h + 2));
  const scene::Camera& cam = scene.camera();
  for (int y = y0 - 1; y <= y1; ++y)
    for (int x = x0 - 1; x <= x1; ++x) {
      CentreSample& c = ring[size_t(y - y0 + 1) * size_t(w + 2) + size_t(x - x0 + 1)];
      if (x < 0 || y < 0 || x >= o.width || y >= o.height) {
        c.shape = -2;
        continue;
      }
      scene::Ray ray{cam.eye,
                     normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height))),
                     0, kInf};
      scene::Hit hit;
      if (scene.intersect(ray, hit)) {
        c.shape = hit.shape;
        c.n = hit.ns;
      }
      if (x >= x0 && x < x1 && y >= y0 && y < y1) {
        c.known = true;
        c.luminance = std::min(1.0f, luminance(res.image.pixels[size_t(y) * size_t(o.width) + size_t(x)]));
      }
    }
  const std::vector<uint8_t> flags = flagPixels(ring, w, h, o);
  if (cache) cache->reset();  // its merged cuts may be of another tile's samples
  const float n = float(g * g);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      if (!flags[size_t(y - y0) * size_t(w) + size_t(x - x0)]) continue;
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
      SubSampleSums sub =
          traceSubSamples(scene, ev, o, x, y, g, counters.stats, counters.primary, counters.secondary, rt, cache);
      size_t i = size_t(y) * size_t(o.width) + size_t(x);
      res.image.pixels[i] = (res.image.pixels[i] + sub.color) / n;
      res.cutSize[i] = float((double(res.cutSize[i]) + sub.cut) / double(n));
      res.shadowRays[i] = float((double(res.shadowRays[i]) + sub.shadowRays) / double(n));
      res.aaFlagged[i] = 1;
      ++counters.aaPixels;
      counters.aaSubSamples += uint64_t(sub.count);
      counters.fallbacks += sub.fallbacks;
    }
}

Color pixelWithSubSamples(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                          const RenderResult& res, int x, int y, lightcuts::EvalStats& stats) {
  uint64_t a = 0, b = 0;
  Color c = renderPixel(scene, ev, o, x, y, stats, a, b).color;
  if (!res.aaFlagged[size_t(y) * size_t(o.width) + size_t(x)]) return c;
  const int g = aaGridSide(o.aaSamples);
  SubSampleSums sub = traceSubSamples(scene, ev, o, x, y, g, stats, a, b, nullptr, nullptr);
  return (c + sub.color) / float(g * g);
}

}  // namespace lc::render
