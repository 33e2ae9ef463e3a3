// Adaptive antialiasing (RenderOptions::aa*, renderer.h): which pixels of a tile to
// re-sample (their centre samples disagree with a neighbour's), where the sub-samples go,
// and tracing them (adaptiveTile, after a tile's centre samples; pixelWithSubSamples for
// the reference pixels). The first parts do not trace, so they are tested alone.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/math.h"
#include "core/rng.h"
#include "lightcuts/evaluator.h"
#include "render/renderer.h"
#include "render/tracer.h"
#include "scene/scene.h"

namespace lc::render {

// What a pixel's centre ray saw.
struct CentreSample {
  int shape = -1;        // the shape hit, -1 for none
  Vec3 n{0, 0, 0};       // its shading normal
  float luminance = 0;   // the pixel's value, clamped to 1 as displayed (when known)
  bool known = false;    // luminance is known (the pixel is in the tile)
};

// Whether two neighbouring centre samples disagree (an edge lies between them).
bool disagree(const CentreSample& a, const CentreSample& b, const RenderOptions& o);

// Whether the luminance along three neighbouring centres a, c, b (in a line) bends by more
// than aaStep of the largest: a step (a shadow's or texture's edge) near c, which a
// straight gradient, however steep, is not.
bool steps(const CentreSample& a, const CentreSample& c, const CentreSample& b, const RenderOptions& o);

// Flags for the w x h pixels of a tile, given their centre samples on a (w + 2) x (h + 2)
// grid (the tile and a one-pixel ring around it, row-major; ring entries outside the image
// have shape -2 and never disagree). A pixel is flagged when any of its 8 neighbours
// disagrees with it, or the luminance steps through it (`steps`).
std::vector<uint8_t> flagPixels(const std::vector<CentreSample>& ring, int w, int h, const RenderOptions& o);

// The side g of the stratified grid for aaSamples = g^2 - 1 sub-samples (0 when invalid).
int aaGridSide(int aaSamples);

// The g^2 - 1 sub-samples of a pixel: correlated multi-jittered on the g x g grid
// (core/multi_jitter.h: one per stratum and one per thin column and row of the g^2), the
// middle stratum's sample, the pixel's centre, left out (the centre sample stands for it).
void aaSubSamplePositions(int g, Rng& rng, std::vector<Vec2>& out);

// The random stream of a pixel's sub-samples (distinct from its fixed-spp stream).
inline uint64_t aaStream(int x, int y, int width, int height) {
  return uint64_t(width) * uint64_t(height) + uint64_t(y) * uint64_t(width) + uint64_t(x);
}

class ReconstructionTile;
struct AaCutCache;

// The tile `rect` after its centre samples: flags the pixels whose centres disagree with a
// neighbour's and re-samples them, counting in `counters`. Every input is the tile's own
// (its pixels, its samples, centre rays probed around it), so the result does not depend
// on the order tiles run in. Under reconstruction cuts (rt, with its cache of merged cuts)
// the sub-samples borrow from the tile's samples (ReconstructionTile::subSampleHook).
void adaptiveTile(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                  RenderResult& res, TileCounters& counters, const TileRect& rect, const ReconstructionTile* rt,
                  AaCutCache* cache);

// After every tile: a tile compared luminance only within itself (its neighbours were not
// rendered yet), so the pixels on tile borders are compared with their neighbours across
// them too, contrast and steps alike, on their centres' luminance (res.centreLuminance).
// The pixels this flags (not flagged already), in row order: the list depends on the
// finished tiles alone, not on their order or on --aa-samples. Without it, a shadow or
// texture edge along a border was left jagged (on an unseen room at 256², 55% of the
// unflagged contrast edges over 2% lay on borders of 16-pixel tiles, against 23% of the
// pixels).
std::vector<std::pair<int, int>> seamPixels(const RenderResult& res, const RenderOptions& o, int tile);

// Re-samples pixel (x, y) on the g x g grid and stores it in `res` (flagged), counting in
// `counters`; rt and cache as for adaptiveTile (null: full cuts, as the seams take).
void resamplePixel(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                   RenderResult& res, TileCounters& counters, int x, int y, int g, const ReconstructionTile* rt,
                   AaCutCache* cache);

// A pixel as the render made it, with another evaluator (brute force for the reference
// pixels, apples to apples): the centre sample, and where antialiasing re-sampled the
// pixel, the same sub-samples (same positions), each with a full evaluation.
Color pixelWithSubSamples(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                          const RenderResult& res, int x, int y, lightcuts::EvalStats& stats);

}  // namespace lc::render
