// The Whitted-style renderer: camera rays per pixel (stratified supersampling), Phong
// shading with direct light from a pluggable LightEvaluator (brute force, Lightcuts or the
// seed's cuts; at primary hits optionally reconstruction cuts, RenderOptions::
// reconstructSpacing), reflection and refraction by recursion. Tiles render in parallel with
// oneTBB; every pixel draws from its own random stream, so the image is the same bit for
// bit at any thread count.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/progress.h"
#include "io/image.h"
#include "lightcuts/evaluator.h"
#include "scene/scene.h"

namespace lc::render {

class WorkShare;

// Antialiasing when spp == 1 (a fixed --spp N > 1 samples every pixel N times instead).
enum class AntiAliasing {
  Off,       // one sample per pixel, at its centre
  Adaptive,  // the centre, then more samples only where neighbouring centres disagree
};

// Its names (core/enum_names.h), read by the functions below and by render --aa. Adaptive's
// words name RenderOptions' thresholds, {normal_degrees}, {contrast_percent} and
// {step_percent}, which antiAliasingHelp fills in.
inline constexpr EnumName<AntiAliasing> kAntiAliasingNames[] = {
    {AntiAliasing::Adaptive, "adaptive",
     "a pixel whose centre ray differs from a neighbour's in shape, in normal by more than {normal_degrees:.0f} "
     "degrees, or in luminance by more than {contrast_percent:g}% (or on a step of {step_percent:g}% along three "
     "pixels) is re-sampled with --aa-samples multi-jittered sub-samples"},
    {AntiAliasing::Off, "off", "the pixel centre only"}};
inline const char* antiAliasingName(AntiAliasing aa) { return enumName(kAntiAliasingNames, aa); }
// Throws lc::Error for another name.
inline AntiAliasing parseAntiAliasing(std::string_view name) {
  return parseEnum(kAntiAliasingNames, name, "antialiasing");
}

struct RenderOptions {
  int width = 512;
  int height = 512;
  int spp = 1;        // samples per pixel, multi-jittered; 1 = the pixel centre (see aa)
  // Adaptive antialiasing (render/adaptive.h), with spp == 1: after a tile's centre samples,
  // a pixel is flagged when one of its 8 neighbours' centre rays
  //   - hits another shape (or nothing where it hits something): a silhouette or crease;
  //   - hits the same shape with a shading normal more than acos(aaNormalCos) away: an
  //     edge between faces of one mesh;
  //   - differs in luminance (each clamped to 1, as displayed) by more than aaContrast of
  //     the larger (at least aaContrastFloor): a shadow or texture boundary, an edge seen
  //     in a mirror;
  //   - or sits on a step in luminance along a line of three centres (aaStep below).
  // (Within a tile, right after its centre samples; across tile borders, whose neighbours
  // were not rendered yet, once every tile is done: seamPixels, adaptive.h.)
  // A flagged pixel is re-sampled on a g x g stratified grid (multi-jittered: also one
  // sample per thin column and row, core/multi_jitter.h; its own random stream, so the
  // image is the same at any thread count): the centre sample stands for
  // the middle stratum, aaSamples = g^2 - 1 new sub-samples fill the others, and the pixel
  // is their mean. Sub-samples borrow the tile's reconstruction samples where they lie on
  // the same surface (else a full lightcut). Measured on the demo (docs/LIGHTCUTS.md).
  AntiAliasing aa = AntiAliasing::Adaptive;
  int aaSamples = 80;            // g^2 - 1 for odd g: 8 (3 x 3), 24 (5 x 5), 48 (7 x 7) or 80 (9 x 9)
  float aaContrast = 0.25f;      // relative luminance contrast that flags a pixel (docs/LIGHTCUTS.md)
  float aaContrastFloor = 0.02f; // luminance below which differences do not count relative
  // Also flagged: a pixel where the luminance along a row, column or diagonal of three
  // centres bends by more than aaStep of the largest (|a + b - 2c|): a step of lower contrast
  // than aaContrast (a shadow of one light among several, a texture's edge) that still puts
  // the centre off the pixel's mean, where a straight gradient does not. A step of contrast
  // c puts the centre up to c/2 off; 2% as displayed (sRGB) is about 5% in linear
  // luminance at mid-tones, so steps from 10% are flagged (docs/LIGHTCUTS.md).
  float aaStep = 0.1f;
  float aaNormalCos = 0.9f;      // cos of the normal difference that flags (~25 degrees)
  // From 24 sub-samples, shade a plain (untextured, not mirror or glass) surface once per
  // cell of a 3 x 3 grid; its other sub-samples there measure coverage and take the
  // nearest shaded one's radiance (adaptive.cpp). 80 coverage samples (9 x 9, the default)
  // bring the demo's edge pixels within 2% of a 256-spp reference on 99.2% of them, 48 on
  // 98.8% (docs/LIGHTCUTS.md).
  bool aaDecoupled = true;
  // ... unless that surface's shaded samples in the pixel differ in luminance by more than
  // this share of the largest (a shadow's or highlight's edge): then it is shaded at every
  // sub-sample up to 7 x 7, and at 49 of them on the 9 x 9 grid.
  float aaShadingSpread = 0.25f;
  int threads = 0;    // 0 = all cores
  int maxDepth = 5;   // reflection/refraction recursion depth
  uint64_t seed = 1;
  // Also evaluate K pixels (spread over the image) with brute force, to report the
  // measured error and the brute-force time the full image would take.
  int referencePixels = 0;
  // Reconstruction cuts (lightcuts only; lightcuts/reconstruction.h): a full lightcut at
  // every Nth pixel in x and y, the primary hits in between rebuilt from the four around
  // them when they lie on the same surface. 0 = a full lightcut everywhere; 1 = a full
  // lightcut at every pixel centre, the pixel's other points (antialiasing's sub-samples,
  // spp's samples) rebuilt from the centres around them.
  int reconstructSpacing = 0;
  // Larger cells first (a multiple of reconstructSpacing by a power of two; 0 = none): a
  // cell of this size is rebuilt from its four corner samples when they lie on one surface
  // and the nodes of their merged cut they disagree about hold little of its light (see
  // kCoarseMaxDisagreement in reconstruction_tiles.h); otherwise it splits down to
  // reconstructSpacing (and below, where pixels are not served).
  int reconstructCoarseSpacing = 0;
  // A cell of reconstructSpacing pixels or less, whose four corner samples lie on one
  // surface, splits in four (new samples at the parts' corners) when the nodes the corners
  // disagree about hold more than this share of their merged cut's unshadowed light: shadow
  // boundaries cross it densely, and there a shadow thinner than the spacing, which all
  // four corners miss, is likely (thin shelves and posts). Those nodes get a ray at every
  // point of the cell anyway, so its samples cost few more rays (more bounds work). 1 =
  // never. 0.2 was measured: unseen warehouses of thin shelves from 1.83% and 1.68% to 0.95%
  // and 0.83% of pixels over 2%, the suite's interiors no worse, shadow rays per point -8%
  // to +7%, render time +4% to +19% (docs/BENCHMARKS.md, "Cells split where their samples
  // disagree").
  float reconstructSplit = 0.2f;
  // Reconstruction cuts: where a rebuilt point's group probe finds a group of its light
  // hidden that every sample saw (or lit that every sample found hidden), and the group
  // alone could put the point over --error (lightcuts::refutingProbeShare), the samples
  // stepped over a shadow edge: the point's cell splits in four, with new samples at the
  // parts' corners (the points it had rebuilt are rebuilt again from the nearer samples),
  // and an antialiasing sub-sample takes a full cut, recorded as a sample for the rest of
  // its pixel (with aaPixelSamples). The point itself re-traces the group either way; its
  // neighbours, whose probes went to other lights or who had none, would not. On by
  // default: unseen warehouses of thin shelves (scripts/gen_warehouse.py, 512 x 512) from
  // 0.51% to 0.22-0.24% of pixels over 2%, blinds 0.51% -> 0.22%, for 5-10% more shadow
  // rays; the church +11% rays, 3-10% time (docs/LIGHTCUTS.md, "Probes that refute their
  // samples").
  bool reconstructRefine = true;
  // Antialiasing under reconstruction cuts: a sub-sample whose samples include one cut off
  // from it by another surface (one occlusion ray per sample, counted as a shadow ray) takes
  // a full cut instead of borrowing (ReconstructionTile::subSampleHook). On by default: a
  // pierced screen, 0.98% -> 0.68% of pixels over 2%, +8% shadow rays.
  bool aaSeparationTest = true;
  // Antialiasing under reconstruction cuts: a sub-sample outside its samples' hull (which
  // it may be when one of them is a neighbouring pixel's) probes for a surface near it,
  // within a reach proportional to how far it lies beyond them (a few short occlusion
  // rays, counted as shadow rays); if one is there, it takes a full cut instead of
  // borrowing (kExtrapolationReach in reconstruction_tiles.h). On by default: an unseen
  // fence seen edge on, 6.2% -> 0.39% of pixels over 2%, blinds 1.03% -> 0.83%; shadow
  // rays per point +3% to +30% on interiors, +19% on the Cornell box (render time +29%;
  // with 10M VPLs at 1920 x 1080 +42%: its creases' full cuts are deep).
  bool aaExtrapolationProbe = true;
  // Antialiasing under reconstruction cuts: a sub-sample that takes a full cut (no sample
  // serves it) is recorded as a sample for the sub-samples after it in its pixel and the
  // next pixels of its tile (PixelSamples in reconstruction_tiles.h). On by default: where
  // one sub-sample on a crease or a board's edge needs a full cut its neighbours mostly do
  // too, and now borrow from it instead. The Cornell box's full cuts at sub-samples 14,512
  // -> 5,108 (shadow rays per point -11%), an unseen fence's pixels over 2% 1.08% -> 0.36%
  // (docs/LIGHTCUTS.md, "Samples inside a pixel").
  bool aaPixelSamples = true;
  // Luminance floor of lightcuts' relative error criterion (ShadingPoint::errorFloor): a
  // cut stops when its error bound is within error x max(estimate, floor), so pixels far
  // darker than the image are held to an absolute error, as the image metric does (its
  // relative error divides by at least 1% of the mean). 0 = none (the published
  // criterion); < 0 = automatic: kAutoErrorFloorFraction of the mean luminance of a
  // kErrorFloorGrid^2 pre-pass over the image without a floor.
  float errorFloor = 0;
  // The least relative error a cut is held to (ShadingPoint::minError): set by the
  // automatic floor's pre-pass to kErrorFloorPrePassError; 0 = the evaluator's --error.
  float minError = 0;
  // Whether cuts may test clusters for being clear (ShadingPoint::clearTests): with the
  // automatic floor, set from its pre-pass (lightcuts::clearTestsPay).
  bool clearTests = true;
  // Set from a signal handler to stop early; the result is marked interrupted.
  std::atomic<bool>* cancel = nullptr;
  // Called from one thread with the fraction done (0..1), about ten times a second.
  std::function<void(double)> progress;
  // The same for the brute-force reference pixels (core/progress.h), called from any
  // worker thread, one at a time.
  ProgressFn referenceProgress = {};
  // Shares the tiles and reference pixels with other processes (a distributed render,
  // app/distributed.h); null: every tile and reference pixel is rendered here.
  WorkShare* share = nullptr;
};

// The help's list of the antialiasing modes (enumHelp), with o's thresholds.
std::string antiAliasingHelp(const RenderOptions& o = {});

struct ReferenceStats {
  int pixels = 0;
  int localPixels = 0;             // of those, computed by this process (a distributed render)
  double bruteSeconds = 0;         // time brute force took on the sampled pixels
  double bruteSecondsEstimate = 0; // extrapolated to the whole image
  double testSeconds = 0;          // time the tested method took on the same pixels
  double meanRelativeError = 0;
  double p99RelativeError = 0;
  double maxRelativeError = 0;
  double fractionOver2pct = 0;
  // The relative error that fractionOver2pct counts beyond (--stats: threshold).
  static constexpr double kThreshold = 0.02;
  double bruteLightsPerShadingPoint = 0;
  // The worst pixels, worst first (at most kWorstPixels; --stats: worst_pixels): where to
  // look in the image.
  struct Pixel {
    int x = 0, y = 0;
    float reference = 0, test = 0;  // luminance
    double relativeError = 0;
  };
  static constexpr size_t kWorstPixels = 16;
  std::vector<Pixel> worst;
};

// --error-floor auto: half the image metric's floor (1% of the mean luminance), estimated
// from a pre-pass of 32 x 32 pixel centres.
constexpr float kAutoErrorFloorFraction = 0.005f;
constexpr int kErrorFloorGrid = 32;
// The pre-pass holds each pixel to at least this relative error: its mean, and so the
// floor, is then within this of the mean of exact pixels (in practice far closer, the
// pixels' errors being of both signs), and the floor is a fraction of the metric's with
// room to spare. At 2% the pre-pass cost 7% of a 64 x 64 render (docs/LIGHTCUTS.md,
// "Error floor").
constexpr float kErrorFloorPrePassError = 0.1f;

struct RenderStats {
  double seconds = 0;  // with the error floor's pre-pass
  float errorFloor = 0;  // the floor used (RenderOptions::errorFloor, resolved)
  uint64_t errorFloorPixels = 0;  // pixels of the automatic floor's pre-pass
  lightcuts::EvalStats prePass;   // the pre-pass's counts (its clear tests, above all)
  bool clearTests = true;         // RenderOptions::clearTests, resolved
  double tileSeconds = 0;  // from the start until this process's last tile was rendered
  uint64_t tiles = 0;      // tiles rendered here
  uint64_t pixels = 0;     // pixels of those tiles
  uint64_t primaryRays = 0;
  uint64_t reconstructionSamples = 0;  // full lightcuts recorded as samples
  uint64_t reconstructionFallbacks = 0;  // primary hits whose samples did not match: full cuts
  uint64_t reconstructionCoarseCells = 0;  // cells of reconstructCoarseSpacing kept whole
  uint64_t reconstructionSplitCells = 0;   // cells split for their samples' disagreement (reconstructSplit)
  uint64_t reconstructionRefinedCells = 0;  // cells split for a refuting group probe (reconstructRefine)
  uint64_t secondaryRays = 0;  // reflection and refraction
  uint64_t aaPixels = 0;       // pixels re-sampled by adaptive antialiasing
  uint64_t aaSeamPixels = 0;   // of them, those flagged across tile borders (seamPixels)
  uint64_t aaSubSamples = 0;   // their extra camera rays (also in primaryRays)
  lightcuts::EvalStats eval;
  ReferenceStats reference;
};

struct RenderResult {
  io::Image image;
  std::vector<float> cutSize;  // per pixel: cut nodes summed over its shading points / spp
  std::vector<float> shadowRays;  // per pixel: shadow rays over its samples / samples
  std::vector<uint8_t> aaFlagged;  // per pixel: 1 when adaptive antialiasing re-sampled it
  // Per pixel: its centre sample's luminance as adaptive antialiasing compares it (clamped
  // to 1), kept for the comparisons across tile borders (seamPixels).
  std::vector<float> centreLuminance;
  RenderStats stats;
  bool interrupted = false;
  std::vector<uint8_t> done;   // per pixel: 1 when rendered (an interrupted render is partial)
};

// A tile of the image: pixels [x0, x1) x [y0, y1).
struct TileRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// The tiles of one render, numbered in raster order. Their size depends on the options
// (whole cells of reconstruction cuts), so every process of a distributed render, given
// the same options, sees the same grid.
struct TileGrid {
  int width = 0, height = 0, tile = 16, tilesX = 0, tilesY = 0;
  int count() const { return tilesX * tilesY; }
  TileRect rect(int t) const;
};
TileGrid tileGrid(const RenderOptions& options, const lightcuts::LightEvaluator& evaluator);

// Hands a render's tiles and reference pixels out over several processes and gathers them
// on one (an MPI job, app/distributed.h; the renderer itself knows nothing of MPI). Every
// pixel depends only on the scene, the options and its coordinates (reconstruction cuts'
// samples on tile edges included), so the image does not depend on which process renders
// which tile. render() asks next() from its worker threads until it gives -1, passes each
// finished tile to rendered(), then calls endTiles(); on the gathering process the other
// processes' tiles arrive in the result meanwhile.
class WorkShare {
 public:
  virtual ~WorkShare() = default;
  // Before the first tile. `result` (sized for the whole image) is where tiles rendered
  // elsewhere are stored on the gathering process.
  virtual void begin(const TileGrid& grid, RenderResult& result) = 0;
  // The next tile to render here, or -1 when none is left (or on cancel). Called from any
  // worker thread, concurrently; may wait for the tile to arrive.
  virtual int next() = 0;
  // Tile `tile` is rendered in `result` (its pixels, from `grid.rect(tile)`); called from
  // the thread that rendered it. A tile left by a cancel is not passed on.
  virtual void rendered(int tile, const RenderResult& result) = 0;
  // Tiles done over all processes (0..1), for the progress bar.
  virtual double fractionDone() const = 0;
  // After this process's last tile: the gathering process waits for every tile (or a
  // cancel); the others send theirs.
  virtual void endTiles() = 0;
  // Whether reference pixel i is computed here.
  virtual bool ownsReference(size_t i) const = 0;
  // After this process's reference pixels: the gathering process receives the others'
  // colours into `reference` (by index) and adds their brute-force statistics to `brute`;
  // the others send theirs.
  virtual void gatherReference(std::vector<Color>& reference, lightcuts::EvalStats& brute) = 0;
  // Whether this process gathers the image; elsewhere the result holds only the tiles
  // rendered there, and the reference statistics are left out.
  virtual bool gathers() const = 0;
};

RenderResult render(const scene::Scene& scene, const lightcuts::LightEvaluator& evaluator,
                    const RenderOptions& options);

// Per-pixel auxiliary outputs (AOVs) at the pixel centre's primary hit: the material's
// diffuse colour (albedo, texture applied), the shading normal (world space) and the
// distance along the camera ray (depth); a ray that hits nothing gives 0, 0 and +inf.
struct PixelAovs {
  std::vector<Color> albedo;
  std::vector<Vec3> normal;
  std::vector<float> depth;
};
PixelAovs primaryAovs(const scene::Scene& scene, const RenderOptions& options);

}  // namespace lc::render
