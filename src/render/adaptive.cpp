#include "render/adaptive.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"
#include "core/multi_jitter.h"
#include "render/reconstruction_tiles.h"

namespace lc::render {

std::string antiAliasingHelp(const RenderOptions& o) {
  return fmt::format(fmt::runtime(enumHelp(kAntiAliasingNames)),
                     fmt::arg("normal_degrees", std::acos(o.aaNormalCos) * 180 / kPi),
                     fmt::arg("contrast_percent", 100 * o.aaContrast), fmt::arg("step_percent", 100 * o.aaStep));
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

bool steps(const CentreSample& a, const CentreSample& c, const CentreSample& b, const RenderOptions& o) {
  if (!a.known || !c.known || !b.known || o.aaStep <= 0) return false;
  const float la = std::min(a.luminance, 1.0f), lc = std::min(c.luminance, 1.0f), lb = std::min(b.luminance, 1.0f);
  const float hi = std::max({la, lb, lc, o.aaContrastFloor});
  return std::fabs(la + lb - 2 * lc) > o.aaStep * hi;
}

namespace {

// Whether a pixel of centre c is flagged by its neighbours: one that disagrees, or a step
// through c along a row, column or diagonal of three centres. nb(dx, dy) is the neighbour
// at that offset; use(dx, dy) whether it is compared (a line when either end is).
// flagPixels compares every neighbour of a tile's pixel, seamPixels those across a border.
template <class Neighbour, class Use>
bool flaggedBy(const CentreSample& c, Neighbour nb, Use use, const RenderOptions& o) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if ((dx || dy) && use(dx, dy) && disagree(c, nb(dx, dy), o)) return true;
  constexpr int kLineDx[4] = {1, 0, 1, 1}, kLineDy[4] = {0, 1, 1, -1};
  for (int k = 0; k < 4; ++k) {
    const int dx = kLineDx[k], dy = kLineDy[k];
    if ((use(-dx, -dy) || use(dx, dy)) && steps(nb(-dx, -dy), c, nb(dx, dy), o)) return true;
  }
  return false;
}

}  // namespace

std::vector<uint8_t> flagPixels(const std::vector<CentreSample>& ring, int w, int h, const RenderOptions& o) {
  std::vector<uint8_t> flags(size_t(w) * size_t(h), 0);
  const int rw = w + 2;
  auto at = [&](int x, int y) -> const CentreSample& { return ring[size_t(y + 1) * size_t(rw) + size_t(x + 1)]; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      auto nb = [&](int dx, int dy) -> const CentreSample& { return at(x + dx, y + dy); };
      flags[size_t(y) * size_t(w) + size_t(x)] = flaggedBy(at(x, y), nb, [](int, int) { return true; }, o);
    }
  return flags;
}

int aaGridSide(int aaSamples) {
  for (int g = 3; g <= 15; g += 2)
    if (g * g - 1 == aaSamples) return g;
  return 0;
}

void aaSubSamplePositions(int g, Rng& rng, std::vector<Vec2>& out) {
  multiJittered(g, g, rng, out, /*keepMiddle=*/true);
  out.erase(out.begin() + (g * g) / 2);  // the centre sample's
}

namespace {

// A textured, mirror or glass surface, and one whose shaded sub-samples disagree, is shaded
// at up to one sub-sample per cell of a grid of this side: every sub-sample up to 48 (7 x 7
// with the centre), 49 of 80; the others take the nearest shaded one's radiance. Without the
// cap, 80 sub-samples cost 1.4 times 48 on the luminous object's mirrors (256², 35.0 s
// against 24.7 s; with it 26.4 s) and 1.2 times on the Roman hall's textured floor.
constexpr int kFineShadingSide = 7;

// What a pixel's sub-samples add: their radiance, cut nodes and shadow rays, summed.
struct SubSampleSums {
  Color color{0};
  double cut = 0, shadowRays = 0;
  int count = 0;
  int shaded = 0;  // of them, those shaded (the others took a shaded one's radiance)
  uint64_t fallbacks = 0;  // sub-samples no reconstruction sample could serve
};

float dist2(const Vec2& a, const Vec2& b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y); }

// A diffuse texture on a purely diffuse material (no specular, mirror or glass): its
// sub-samples share shading like a plain surface's, each taking the shaded one's light scaled
// by its own texel (the ratio of diffuse colours), exact where the light is the same over
// the cell. Shaded once per cell of the 3 x 3 grid instead of the fine grid's (with its
// textured floor, bench/aa_study.ray took 7.4 times its 1-spp render's time at up to 49
// shadings a pixel, 4.8 with this). Not with a specular term: the ratio would scale the highlight by
// the texture too (on the Roman hall's glossy mosaic a first version that did moved 5.4% of
// the pixels by over 2% at 128², the new flags' share included).
bool textureRatio(const scene::Material& m) {
  return m.diffuse.texture && m.specular.isBlack() && m.reflective.isBlack() && m.transmissive.isBlack() &&
         !m.emissive.texture && !m.ambient.texture && !m.shininess.texture;
}

// Whether a hit on this material must be shaded at every sub-sample: a mirror or glass
// shows other surfaces, a texture varies within the pixel (but see textureRatio).
bool shadeEverySubSample(const scene::Material& m) {
  return !textureRatio(m) && (!m.reflective.isBlack() || !m.transmissive.isBlack() || m.diffuse.texture ||
                              m.specular.texture || m.emissive.texture || m.ambient.texture || m.shininess.texture);
}

// Radiance c of a hit with diffuse colour kdFrom, moved to a point of the same surface whose
// diffuse colour is kdTo: the part above `base` (emission and ambient, untextured) scaled
// per channel (a channel of diffuse colour 0 is kept as it is).
Color retexture(const Color& c, const Color& base, const Color& kdFrom, const Color& kdTo) {
  Color out = c;
  for (int k = 0; k < 3; ++k)
    if (kdFrom[k] > 0) out[k] = base[k] + (c[k] - base[k]) * (kdTo[k] / kdFrom[k]);
  return out;
}

// The light a shaded sample received, with its texel divided out (its spread within a
// pixel is the light's, not the texture's).
float untexturedLuminance(const Color& c, const Color& base, const Color& kd) {
  return luminance(retexture(c, base, kd, Color(1)));
}

// The sub-samples of pixel (x, y) on the g x g grid; under reconstruction cuts (rt) each
// borrows from the tile's samples (ReconstructionTile::subSampleHook).
//
// Coverage and shading are decoupled (as MSAA and Ragan-Kelley et al. 2011 do): every
// sub-sample's primary ray finds which surface it sees, but on a plain diffuse or glossy
// surface only the first sub-sample of that surface in each cell of a 3 x 3 grid over the
// pixel is shaded, and the others take the radiance of the nearest shaded one on the same
// surface (the pixel's centre, of radiance `centre`, counts as shaded). An edge pixel's
// error is mostly which surface covers how much of it, which 80 rays measure for the price
// of a few shadings; light varies little across one surface within a pixel, and where it
// does (the shaded samples disagree) the surface is shaded at every sub-sample (up to 49).
SubSampleSums traceSubSamples(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                              int x, int y, int g, lightcuts::EvalStats& stats, uint64_t& primary,
                              uint64_t& secondary, const ReconstructionTile* rt, AaCutCache* cache,
                              const Color& centre) {
  SubSampleSums sums;
  Rng rng(o.seed, aaStream(x, y, o.width, o.height));
  const scene::Camera& cam = scene.camera();
  const int n = g * g - 1;
  struct Sub {
    Vec2 u;
    scene::Ray ray;
    bool hit = false;
    int surface = -1;  // index into `surfaces`
    const scene::Material* m = nullptr;  // of its hit
    bool byMaterial = false;  // textured, mirror or glass: shares shading by material (below)
    bool shade = true;
    Color c{0};
    bool ratio = false;  // textureRatio: kd and base (emission + ambient) at its hit
    Color kd{0}, base{0};
  };
  static thread_local std::vector<Sub> subs;
  subs.assign(size_t(n), Sub{});
  // Which surface each sub-sample sees, and which of them are shaded.
  const bool decouple = o.aaDecoupled && g > 3;
  // The surfaces the sub-samples see, the centre's first: hits on one tangent plane (normals
  // within aaNormalCos, the point within 1% of the distance of the plane) with the same
  // material values, or misses. Not the shape index: how a scene is cut into shapes (an OBJ
  // read directly or converted) must not change the image. Per cell of the 3 x 3 grid, the
  // surfaces already given a shading sample there.
  struct Surface {
    bool hit;
    Vec3 p, n;
    float t;
    const scene::Material* m;
  };
  std::vector<Surface> surfaces;
  // The centre's texel where its material takes textureRatio.
  bool centreRatio = false;
  Color centreKd{0}, centreBase{0};
  auto texel = [&](const scene::Hit& h, Color& kd, Color& base) {
    const scene::ShadingMaterial sm = scene.shadingMaterial(h);
    kd = sm.kd;
    base = sm.ke + sm.ka * scene.ambient();
  };
  if (decouple) {
    scene::Hit h;
    const scene::Ray c{cam.eye, normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height))),
                       0, kInf};
    const bool hit = scene.intersect(c, h);
    surfaces.push_back(Surface{hit, h.p, h.ns, h.t, hit ? &scene.materialOf(h) : nullptr});
    if (hit && textureRatio(*surfaces[0].m)) {
      centreRatio = true;
      texel(h, centreKd, centreBase);
    }
  }
  auto same = [&](const Surface& a, bool hit, const scene::Hit& h, const scene::Material* m) {
    if (a.hit != hit) return false;
    if (!hit) return true;
    return dot(a.n, h.ns) >= o.aaNormalCos && std::fabs(dot(h.p - a.p, a.n)) <= 0.01f * a.t &&
           (a.m == m || (a.m->diffuse.value == m->diffuse.value && a.m->specular.value == m->specular.value &&
                         a.m->emissive.value == m->emissive.value && a.m->ambient.value == m->ambient.value &&
                         a.m->shininess.value == m->shininess.value));
  };
  static thread_local std::vector<Vec2> positions;
  aaSubSamplePositions(g, rng, positions);
  std::vector<std::pair<int, int>> shadedInCell;  // (cell, surface)
  if (decouple) shadedInCell.emplace_back(4, 0);  // the centre sample
  // The fine grid (kFineShadingSide): a surface shaded at every sub-sample (textured, a
  // mirror or glass, or shaded samples that disagree, below) is shaded at one per fine cell.
  const int side = std::min(g, kFineShadingSide);
  auto fineCell = [side](const Vec2& u) {
    return std::min(side - 1, int(u.x * float(side))) + side * std::min(side - 1, int(u.y * float(side)));
  };
  // (fine cell, material) shaded for such surfaces: keyed by the material, not the surface,
  // since which surface a sub-sample joins is a threshold decision that float-level
  // differences in the hits can flip (an OBJ read directly and converted, ObjRoundTrip).
  std::vector<std::pair<int, const scene::Material*>> shadedInFineCell;
  if (decouple && surfaces[0].m) shadedInFineCell.emplace_back(fineCell(Vec2(0.5f, 0.5f)), surfaces[0].m);
  // (cell of the 3 x 3 grid, material) shaded for diffuse textures (textureRatio).
  std::vector<std::pair<int, const scene::Material*>> shadedInCoarseCell;
  if (centreRatio) shadedInCoarseCell.emplace_back(4, surfaces[0].m);
  for (int s = 0; s < n; ++s) {
    Sub& b = subs[size_t(s)];
    b.u = positions[size_t(s)];
    b.ray = scene::Ray{cam.eye,
                       normalize(cam.direction((float(x) + b.u.x) / float(o.width), (float(y) + b.u.y) / float(o.height))),
                       0, kInf};
    if (!decouple) continue;
    scene::Hit hit;
    b.hit = scene.intersect(b.ray, hit);
    ++primary;
    const scene::Material* m = b.hit ? &scene.materialOf(hit) : nullptr;
    for (size_t k = 0; k < surfaces.size() && b.surface < 0; ++k)
      if (same(surfaces[k], b.hit, hit, m)) b.surface = int(k);
    if (b.surface < 0) {
      b.surface = int(surfaces.size());
      surfaces.push_back(Surface{b.hit, hit.p, hit.ns, hit.t, m});
    }
    b.m = m;
    const int cell = std::min(2, int(b.u.x * 3)) + 3 * std::min(2, int(b.u.y * 3));
    if (m && textureRatio(*m)) {
      // Shared by material, as the fine cells are (below: surfaces are a threshold decision
      // that an OBJ read directly and converted may take differently), on the 3 x 3 grid.
      b.ratio = b.byMaterial = true;
      texel(hit, b.kd, b.base);
      const std::pair<int, const scene::Material*> key{cell, m};
      if (std::find(shadedInCoarseCell.begin(), shadedInCoarseCell.end(), key) != shadedInCoarseCell.end()) {
        b.shade = false;
      } else {
        shadedInCoarseCell.push_back(key);
      }
      continue;
    }
    if (m && shadeEverySubSample(*m)) {
      b.byMaterial = true;
      const std::pair<int, const scene::Material*> fine{fineCell(b.u), m};
      if (std::find(shadedInFineCell.begin(), shadedInFineCell.end(), fine) != shadedInFineCell.end()) {
        b.shade = false;
      } else {
        shadedInFineCell.push_back(fine);
      }
      continue;
    }
    const std::pair<int, int> key{cell, b.surface};
    if (std::find(shadedInCell.begin(), shadedInCell.end(), key) != shadedInCell.end()) {
      b.shade = false;
    } else {
      shadedInCell.push_back(key);
    }
  }
  // Shades sub-sample b (a full trace from its primary ray).
  auto shade = [&](Sub& b) {
    PrimaryHook hook;
    const CutSample* chosen[4];
    const uint64_t rays0 = stats.shadowRays;
    if (rt) rt->subSampleHook(b.ray, x, y, b.u, hook, chosen, *cache);
    stats.shadowRays += hook.separationRays;  // occlusion rays of the light's estimate
    Tracer tr{scene, ev, o.maxDepth, stats, rt ? &hook : nullptr};
    tr.cutSettingsFrom(o);  // as at the pixel's centre (renderPixel)
    if (!decouple) ++primary;
    Color c = tr.trace(b.ray, 0);
    if (!isFinite(c)) c = Color(0);
    b.c = c;
    sums.cut += double(tr.cutNodes);
    sums.shadowRays += double(stats.shadowRays - rays0);
    secondary += tr.secondaryRays;
    sums.fallbacks += hook.fallbacks;
    ++sums.shaded;
  };
  for (Sub& b : subs)
    if (b.shade) shade(b);
  if (decouple) {
    // A surface whose shaded samples disagree (a hard shadow's edge, a highlight crosses the
    // pixel) is shaded at every sub-sample after all: coverage alone does not measure it.
    // `member` picks the group's sub-samples; `centreIn`, whether the centre is one of them.
    // (On a diffuse texture, the light is compared: each sample's texel divided out.)
    auto refine = [&](auto member, bool centreIn, float centreLum) {
      float lo = kInf, hi = 0;
      if (centreIn) lo = hi = centreLum;
      bool pending = false;
      for (const Sub& b : subs) {
        if (!member(b)) continue;
        pending |= !b.shade;
        if (!b.shade) continue;
        const float l = b.ratio ? untexturedLuminance(b.c, b.base, b.kd) : luminance(b.c);
        lo = std::min(lo, l);
        hi = std::max(hi, l);
      }
      if (!pending || !(hi - lo > o.aaShadingSpread * std::max(hi, o.aaContrastFloor))) return;
      // Up to one shaded sample per cell of the fine grid (every sub-sample up to 7 x 7;
      // with 80 sub-samples 49 of them): a finer grid of coverage rays does not make
      // the shading's own sampling finer (on the demo, all 80 cost a fifth more shadow rays).
      std::array<bool, kFineShadingSide * kFineShadingSide> taken{};
      if (centreIn) taken[size_t(fineCell(Vec2(0.5f, 0.5f)))] = true;
      for (const Sub& b : subs)
        if (member(b) && b.shade) taken[size_t(fineCell(b.u))] = true;
      for (Sub& b : subs)
        if (member(b) && !b.shade && !taken[size_t(fineCell(b.u))]) {
          taken[size_t(fineCell(b.u))] = true;
          b.shade = true;
          shade(b);
        }
    };
    for (size_t k = 0; k < shadedInCell.size(); ++k) {
      const int surface = shadedInCell[k].second;
      bool seen = false;
      for (size_t j = 0; j < k; ++j) seen |= shadedInCell[j].second == surface;
      if (seen) continue;
      refine([&](const Sub& b) { return b.surface == surface && !b.byMaterial; }, surface == 0 && !centreRatio,
             luminance(centre));
    }
    for (size_t k = 0; k < shadedInCoarseCell.size(); ++k) {
      const scene::Material* m = shadedInCoarseCell[k].second;
      bool seen = false;
      for (size_t j = 0; j < k; ++j) seen |= shadedInCoarseCell[j].second == m;
      if (seen) continue;
      const bool centreIn = centreRatio && surfaces[0].m == m;
      refine([&](const Sub& b) { return b.ratio && b.m == m; }, centreIn,
             centreIn ? untexturedLuminance(centre, centreBase, centreKd) : 0.0f);
    }
  }
  for (int s = 0; s < n; ++s) {
    Sub& b = subs[size_t(s)];
    if (!b.shade) {
      // The nearest shaded sub-sample on the same surface (the centre included), or of the
      // same material where shading is shared by material (one is in its fine cell).
      // On a diffuse texture, scaled by the ratio of its texel to the shaded one's.
      float best = kInf;
      Color c = centre;
      const Sub* from = nullptr;  // null: the centre
      auto alike = [&](const Sub& o2) { return b.byMaterial ? o2.byMaterial && o2.m == b.m : o2.surface == b.surface; };
      if (b.byMaterial ? surfaces[0].m == b.m : b.surface == 0) best = dist2(b.u, Vec2(0.5f, 0.5f));
      for (const Sub& o2 : subs)
        if (o2.shade && alike(o2)) {
          const float d = dist2(b.u, o2.u);
          if (d < best) {
            best = d;
            c = o2.c;
            from = &o2;
          }
        }
      if (b.ratio) {
        if (from && from->ratio) {
          c = retexture(c, from->base, from->kd, b.kd);
        } else if (!from && centreRatio) {
          c = retexture(c, centreBase, centreKd, b.kd);
        }
      }
      b.c = c;
    }
    sums.color += b.c;
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
        const size_t i = size_t(y) * size_t(o.width) + size_t(x);
        c.luminance = std::min(1.0f, luminance(res.image.pixels[i]));
        if (i < res.centreLuminance.size()) res.centreLuminance[i] = c.luminance;
      }
    }
  const std::vector<uint8_t> flags = flagPixels(ring, w, h, o);
  if (cache) cache->reset();  // its merged cuts may be of another tile's samples
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      if (!flags[size_t(y - y0) * size_t(w) + size_t(x - x0)]) continue;
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
      resamplePixel(scene, ev, o, res, counters, x, y, g, rt, cache);
    }
}

std::vector<std::pair<int, int>> seamPixels(const RenderResult& res, const RenderOptions& o, int tile) {
  std::vector<std::pair<int, int>> out;
  if (o.aa != AntiAliasing::Adaptive || o.spp != 1 || aaGridSide(o.aaSamples) == 0 || tile <= 0) return out;
  const int W = o.width, H = o.height;
  if (res.centreLuminance.size() != size_t(W) * size_t(H)) return out;
  // The centres' luminance, as the tiles compared it: the flags do not depend on what the
  // re-sampled neighbours came to (nor on --aa-samples).
  auto lum = [&](int x, int y) {
    CentreSample c;  // shape -1 on both sides: only luminance is compared here
    if (x < 0 || y < 0 || x >= W || y >= H) {
      c.shape = -2;  // outside the image: never disagrees, no luminance
      return c;
    }
    c.known = true;
    c.luminance = res.centreLuminance[size_t(y) * size_t(W) + size_t(x)];
    return c;
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int inX = x % tile, inY = y % tile;
      if (inX != 0 && inX != tile - 1 && inY != 0 && inY != tile - 1) continue;  // not on a border
      if (res.aaFlagged[size_t(y) * size_t(W) + size_t(x)]) continue;
      // Only neighbours in another tile: shape and normal were compared there already.
      auto across = [&](int dx, int dy) { return (x + dx) / tile != x / tile || (y + dy) / tile != y / tile; };
      auto nb = [&](int dx, int dy) { return lum(x + dx, y + dy); };
      if (flaggedBy(lum(x, y), nb, across, o)) out.emplace_back(x, y);
    }
  return out;
}

void resamplePixel(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                   RenderResult& res, TileCounters& counters, int x, int y, int g, const ReconstructionTile* rt,
                   AaCutCache* cache) {
  const size_t i = size_t(y) * size_t(o.width) + size_t(x);
  SubSampleSums sub = traceSubSamples(scene, ev, o, x, y, g, counters.stats, counters.primary, counters.secondary,
                                      rt, cache, res.image.pixels[i]);
  res.image.pixels[i] = (res.image.pixels[i] + sub.color) / float(g * g);
  // Per shading: the samples that took another's radiance cost no cut.
  const double shadings = 1.0 + sub.shaded;
  res.cutSize[i] = float((double(res.cutSize[i]) + sub.cut) / shadings);
  res.shadowRays[i] = float((double(res.shadowRays[i]) + sub.shadowRays) / shadings);
  res.aaFlagged[i] = 1;
  ++counters.aaPixels;
  counters.aaSubSamples += uint64_t(sub.count);
  counters.fallbacks += sub.fallbacks;
}

Color pixelWithSubSamples(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                          const RenderResult& res, int x, int y, lightcuts::EvalStats& stats) {
  uint64_t a = 0, b = 0;
  Color c = renderPixel(scene, ev, o, x, y, stats, a, b).color;
  if (!res.aaFlagged[size_t(y) * size_t(o.width) + size_t(x)]) return c;
  const int g = aaGridSide(o.aaSamples);
  SubSampleSums sub = traceSubSamples(scene, ev, o, x, y, g, stats, a, b, nullptr, nullptr, c);
  return (c + sub.color) / float(g * g);
}

}  // namespace lc::render
