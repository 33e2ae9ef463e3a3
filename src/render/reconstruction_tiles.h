// Reconstruction cuts in image space (RenderOptions::reconstructSpacing): which pixels get
// a full lightcut as a sample, which samples a primary hit may borrow from, and the tile
// of cells that splits where they cannot serve. Image-space choices stay here in render;
// everything asked of the cuts themselves (lightcuts/reconstruction.h) goes through one
// named interface, CutReconstruction.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "lightcuts/evaluator.h"
#include "lightcuts/reconstruction.h"
#include "render/renderer.h"
#include "render/tracer.h"
#include "scene/scene.h"

namespace lc::render {

// The tiles' interface to lightcuts' reconstruction cuts, all of it: a sample records its
// full lightcut, the cuts of a cell's samples merge into one, a point is lit from a merged
// cut (or in full when no sample serves it), and a coarse cell asks how much of a merged
// cut's light its samples disagree about.
class CutReconstruction {
 public:
  CutReconstruction(const lightcuts::LightEvaluator& ev, const LightSet& lights) : ev_(ev), lights_(lights) {}
  lightcuts::EvalResult record(const lightcuts::ShadingPoint& sp, lightcuts::Visibility& vis,
                               lightcuts::EvalStats& stats, lightcuts::CutRecord& out) const {
    return ev_.evaluateRecorded(sp, vis, stats, out);
  }
  void merge(const lightcuts::CutRecord* const* cuts, int count, lightcuts::MergedCut& out) const {
    ev_.mergeSamples(cuts, count, out);
  }
  lightcuts::EvalResult rebuild(const lightcuts::ShadingPoint& sp, lightcuts::Visibility& vis,
                                lightcuts::EvalStats& stats, const lightcuts::MergedCut& merged) const {
    return ev_.reconstruct(sp, vis, stats, merged);
  }
  lightcuts::EvalResult full(const lightcuts::ShadingPoint& sp, lightcuts::Visibility& vis,
                             lightcuts::EvalStats& stats) const {
    return ev_.evaluate(sp, vis, stats);
  }
  float disagreement(const lightcuts::MergedCut& merged, const Vec3& p, const Vec3& n) const {
    return lightcuts::disagreementShare(lights_, merged, p, n);
  }

 private:
  const lightcuts::LightEvaluator& ev_;
  const LightSet& lights_;
};

// A sample of reconstruction cuts: the lightcut at a pixel centre's primary hit.
struct CutSample {
  lightcuts::CutRecord cut;  // cut.valid is false when the ray shaded nothing
  int shape = -1;
  Vec3 p, n;
};

// A hit and a sample are on one surface when they share the shape, their normals are
// within ~25 degrees, and the sample lies near the hit's tangent plane (within ~12
// degrees of it seen from the hit): one mesh often holds many parallel faces, a column's
// front and the wall behind it.
constexpr float kSampleMinCos = 0.9f;
constexpr float kSampleMaxPlaneSlope = 0.2f;
bool sameSurface(int shapeA, const Vec3& pa, const Vec3& na, int shapeB, const Vec3& pb, const Vec3& nb);

// A sample serves points at most this many times S pixel footprints away (a footprint:
// the point's distance times one pixel's angle). On a surface seen face on, a cell's
// corners are within 1.5 S; seen at a grazing angle, world features shrink in the image
// (the shadows of a row of pews on a far floor become 1-pixel lines that samples S
// pixels apart step over), and there the cells split. 3 was measured: the church within
// 2% on 99% of pixels (0.8% over), the Cornell floor (seen at ~70 degrees) still in
// whole cells.
constexpr float kSampleMaxFootprints = 3.0f;

// A coarse cell (RenderOptions::reconstructCoarseSpacing) stays whole when the nodes its
// corner samples disagree about (a shadow boundary crosses it) hold at most this share of
// their unshadowed light; those nodes get a shadow ray at every point anyway, but many of
// them mean shadow edges the corners may step over (the church's steps and pews). Where
// the disagreement is only the emitter's own terminator (the green emitter's walls: a
// share of 1-5%), the cell stays whole. 0.05 was measured: on the benchmark's scenes the
// pixels over 2% stay as with cells of S (the church 0.63% vs 0.62%; all four corners
// trusted whatever they disagree about, 0.89%), and the emitter needs a third fewer
// samples (docs/LIGHTCUTS.md).
constexpr float kCoarseMaxDisagreement = 0.05f;

// How far, in scene epsilons, the segment between an antialiasing sub-sample and a sample
// on its surface is lifted off the surface when tested for another surface cutting them off
// (ReconstructionTile::subSampleHook): clear of the surface itself, below any surface that
// touches it.
constexpr float kSeparationLift = 8.0f;

// An antialiasing sub-sample outside its samples' hull (it borrows from a sample in a
// neighbouring pixel: RenderOptions::aaExtrapolationProbe) extrapolates their visibility by
// its world distance d from the nearest segment between them. An irradiance cache bounds
// such reuse by the distance to the nearest surface around the point (Ward et al. 1988):
// visibility changes by about d over that distance. So when d exceeds
// kExtrapolationMinFootprints of the sub-sample's pixel footprint, it sends
// kExtrapolationRays short occlusion rays from its surface (the normal, and four tilted
// 45 degrees from it toward the tangent axes), each kExtrapolationReach * d long; if one
// is blocked, a surface near enough to hide different lights from it than from its
// samples is there (the next board of a fence seen edge on, a slat of a blind, the base
// of a box), and it takes a full cut. Measured at 512 x 512, defaults (docs/LIGHTCUTS.md,
// "Sub-samples beyond their samples"): reach 20 and 0.5 footprints bring an unseen fence
// from 6.2% to 0.39% of pixels over 2%, blinds from 1.03% to 0.83%; 10 left the fence at
// 1.6%, 1 footprint the blinds at 1.03%; a ray along the normal alone did nothing for the
// blinds. With pixel samples (PixelSamples), which make full cuts cheap where they gather,
// 0.25 footprints: a fence drawn later 0.36% -> 0.22% of pixels over 2% against brute force,
// a radiator 0.19% -> 0.07%, for 1-5% more shadow rays (a slit of floor between boards
// lets different lights through a quarter of a pixel apart).
constexpr float kExtrapolationReach = 20.0f;
constexpr float kExtrapolationMinFootprints = 0.25f;
constexpr int kExtrapolationRays = 5;

// The merged cuts of one cell of pixels, one per subset of its corner samples, made when
// first needed.
struct CellCuts {
  lightcuts::MergedCut merged[16];
  bool ready[16] = {};
  // Antialiasing's sub-samples: the samples the merged cuts are of (count -1: unknown).
  int aaCount = -1;
  const CutSample* aaSamples[4] = {};
  void reset();
};

// Samples inside antialiased pixels (RenderOptions::aaPixelSamples): the full cuts that
// sub-samples took where no sample could serve them (beyond their samples near a surface,
// cut off from them, or none near), each recorded as a sample at the sub-sample's position
// for the sub-samples after it in its pixel and in the next pixels of the tile (within one
// pixel of it). Pixels and their sub-samples run in a fixed order within a tile and the
// samples are dropped when a tile starts, so the image depends on nothing else (not on the
// thread count). Where one sub-sample on a crease or along a board's side face needs a full
// cut, its neighbours mostly do too; with it as a sample they lie near one, and borrow.
// Samples gather where the image needs them, as cells split (Walter et al. 2005, sec. 5).
// A pixel sample serves sub-samples within kPixelSampleMaxFootprints of it (a face seen
// edge on spreads a pixel far across the world). Near one, a surface was near enough for a
// full cut, and hard shadows there change within a fraction of a pixel: with the probe's
// gate at 0.5 footprints (kExtrapolationMinFootprints) pixel samples put an unseen fence at
// 1.42% of pixels over 2%, against 1.13% without them; at 0.25, 0.45% (docs/LIGHTCUTS.md,
// "Samples inside a pixel").
constexpr float kPixelSampleMaxFootprints = 2.0f;
struct PixelSamples {
  static constexpr int kMax = 32;  // the most recent ones, replaced in turn
  CutSample slot[kMax];
  int px[kMax] = {}, py[kMax] = {};  // their positions, in the hull test's sub-pixel units
  int recorded = 0;  // since the tile started: the next takes slot recorded % kMax
  int count() const { return std::min(recorded, kMax); }
};

// The merged cuts of the last few sets of samples antialiasing's sub-samples borrowed from
// (neighbouring sub-samples, and pixels, mostly borrow from the same ones), replaced in
// turn; and the tile's pixel samples.
struct AaCutCache {
  static constexpr int kEntries = 8;
  CellCuts entries[kEntries];
  int next = 0;
  PixelSamples pixelSamples;
  void reset();
  CellCuts* find(const CutSample* const* set, int k);
  // Drops the merged cuts that use `s` (a pixel sample about to be recorded anew).
  void forget(const CutSample* s);
  // The slot for a new pixel sample at (px, py) (the hull test's sub-pixel units), over the
  // oldest once all PixelSamples::kMax are taken: emptied, its merged cuts forgotten.
  CutSample* newPixelSample(int px, int py);
};

// What happens at a primary hit under reconstruction cuts: the hit records its lightcut as
// a sample, or borrows from samples on its surface, or (none serves it) gets a full cut.
struct PrimaryHook final : PrimaryLight {
  const CutReconstruction* cuts = nullptr;
  CutSample* record = nullptr;                 // record the lightcut here, or
  const CutSample* const* samples = nullptr;   // rebuild the cut from these (distinct)
  int count = 0;
  CellCuts* cell = nullptr;
  Vec3 eye;                   // the camera's position and
  float maxSeparation = kInf;  // how far a sample may be, over the point's distance to it
  int px = 0, py = 0;         // the pixel, and
  int cx[4] = {}, cy[4] = {};  // the samples' pixels
  bool preselected = false;  // samples chosen for this very hit (antialiasing): no hull test
  bool recordFallback = false;  // `record` is a pixel sample (PixelSamples): count it a fallback
  // Antialiasing's sub-samples under RenderOptions::reconstructRefine: a sub-sample whose
  // probe refutes its samples takes a full cut, recorded as a pixel sample in this cache
  // when there is one.
  bool refine = false;
  AaCutCache* aaCache = nullptr;
  uint64_t fallbacks = 0;  // hits no sample could serve: they got a full lightcut
  uint64_t separationRays = 0;  // antialiasing: rays that tested its samples for being cut off,
                                // and for a surface near the sub-sample beyond their hull

  lightcuts::EvalResult light(const scene::Hit& h, const lightcuts::ShadingPoint& sp, lightcuts::Visibility& vis,
                              lightcuts::EvalStats& stats) override;
};

// Whether pixel (x, y) lies in the convex hull of the samples in `mask`: a point borrows
// only between samples on its surface, never beyond them. (Toward an edge a point may be
// nearer lights than any sample was, and need a finer cut.) Integer, so exact.
bool insideSamples(const PrimaryHook& h, unsigned mask);

// The samples that serve a hit on `shape` at p with normal n, or 0 when none can: those
// on its surface (across an edge, visibility borrowed from the other side would be
// wrong), if the hit lies between them.
unsigned servingSamples(const PrimaryHook& h, int shape, const Vec3& p, const Vec3& n);

// Samples on the lines where tiles meet, shared by the tiles on both sides: the first
// tile to need one computes it, the other reads it. A tile that finds one being computed
// computes its own copy (the same values: a sample depends only on its pixel), so no
// thread waits on another. Each entry counts the tiles that may use it (two, four where
// four tiles meet); when the last of them is done the sample's cut is freed, so only the
// lines along unfinished tiles hold memory.
class EdgeSamples {
 public:
  EdgeSamples(int width, int height, int tile);

  struct Entry {
    std::atomic<uint8_t> state{0};  // kEmpty, kBusy or kReady
    std::atomic<uint8_t> users{0};  // tiles that may still read it
    CutSample sample;
    PixelResult pixel;
  };
  static constexpr uint8_t kEmpty = 0, kBusy = 1, kReady = 2;

  // The entry of pixel (x, y) if it lies on a line between tiles, else null.
  Entry* at(int x, int y);

  // The tile of pixels [x0, x1) x [y0, y1) is done: it reads none of the samples on its
  // border again (its cells' corners reach x1 and y1, clipped to the image).
  void tileDone(int x0, int y0, int x1, int y1);

 private:
  bool onLineX(int x) const { return x > 0 && x % tile_ == 0 && x / tile_ <= linesX_; }
  bool onLineY(int y) const { return y > 0 && y % tile_ == 0 && y / tile_ <= linesY_; }

  int width_, height_, tile_, linesX_, linesY_;
  std::vector<Entry> entries_;
};

// What every tile of one render under reconstruction cuts shares.
struct ReconstructionRender {
  ReconstructionRender(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o,
                       int tile);
  const scene::Scene& scene;
  const lightcuts::LightEvaluator& ev;
  CutReconstruction cuts;
  const RenderOptions& o;
  RenderOptions centre;  // o with one sample per pixel, through its centre, and no progress
  int spacing;           // S: samples every S pixels (RenderOptions::reconstructSpacing)
  int coarse;            // C >= S: the cells tiles start from (reconstructCoarseSpacing)
  EdgeSamples edges;     // the samples on the lines between tiles of `tile` pixels
};

// A thread's buffers for the tiles it renders, reused from tile to tile.
struct ReconstructionScratch {
  std::vector<CutSample> slots;          // the tile's samples, per pixel (its far edges too)
  std::vector<uint8_t> state;            // per slot: ReconstructionTile::kDone when its pixel is stored
  std::vector<const CutSample*> shared;  // per slot: its sample (the slot's, or an EdgeSamples one), once made
  CellCuts cell;                         // the merged cuts of the current cell
  std::vector<uint32_t> rebuilt;         // the slots of the pixels the current cell rebuilt
};

// One tile under reconstruction cuts. The tile is cut into cells of S x S pixels with
// samples (full lightcuts through pixel centres) on their corners. A pixel whose hit lies
// inside the samples on its surface (servingSamples) is rebuilt from them; where some are
// not, the cell splits in four, with new samples on the corners of the parts, down to
// single pixels: samples gather along edges and silhouettes, smooth regions share a few
// (the adaptive image sampling of Walter et al. 2005, sec. 5). A cell also splits where
// its corners disagree about much of their light (RenderOptions::reconstructSplit), so
// samples gather where shadow edges are dense too, and where a point's probe finds a shadow
// edge its corners stepped over (RenderOptions::reconstructRefine). Every choice depends only
// on the hits, so the image does not depend on the order tiles run in. Corners on the
// tile's right and bottom edges belong to the next tiles; they are shared with them
// (EdgeSamples) and stored by the tile they belong to.
class ReconstructionTile {
 public:
  static constexpr uint8_t kDone = 1;

  ReconstructionTile(ReconstructionRender& render, const TileRect& rect, ReconstructionScratch& scratch,
                     TileCounters& counters, RenderResult& res);

  // Renders the tile's pixels into the result: cells of C x C pixels (the coarse spacing,
  // or S), split as they need.
  void run();

  // Sets `hook` up for an antialiasing sub-sample of pixel (x, y) at offset u, along `ray`:
  // it borrows from the tile's samples on its surface, the nearest one in each quadrant
  // around the sub-sample's own position within two cells, used when the sub-sample lies
  // between them (tested at 1/16 pixel) or one of them is a neighbouring pixel (samples
  // gather along edges, where a sub-sample may hit the surface beyond); else (no samples)
  // it gets a full lightcut. (Quadrants around the pixel instead let the pixel's own
  // sample, where it is one, win all four, and sub-samples on a contact line borrowed from
  // it alone: up to 13% off.) One beyond its samples (the neighbouring pixel's case) also
  // gets a full lightcut where a surface lies near it (surfaceNear). A sub-sample that gets
  // a full lightcut becomes a pixel sample (PixelSamples, in `cache`) for the sub-samples
  // after it. `chosen` holds the samples; the merged cuts come from `cache`.
  void subSampleHook(const scene::Ray& ray, int x, int y, Vec2 u, PrimaryHook& hook, const CutSample** chosen,
                     AaCutCache& cache) const;

 private:
  size_t slot(int x, int y) const { return size_t(y - y0_) * size_t(x1_ - x0_ + 1) + size_t(x - x0_); }
  const CutSample& sample(int x, int y);
  std::optional<float> cornersDisagreement(const CutSample* const* corners, int n);
  bool probe(int x, int y, int& shape, Vec3& p, Vec3& n) const;
  bool surfaceNear(const scene::Hit& hit, float footprint, const CutSample* const* chosen, int k,
                   PrimaryHook& hook) const;
  void cellPixels(int cx, int cy, int w, int h);

  ReconstructionRender& r_;
  const RenderOptions& o_;
  ReconstructionScratch& scratch_;
  TileCounters& n_;
  RenderResult& res_;
  int x0_, y0_, x1_, y1_;      // the tile's pixels: [x0, x1) x [y0, y1)
  float maxSeparation_ = kInf;  // the footprint limit of cells of S pixels
  float pixelAngle_ = 0;        // one pixel's angle at the image centre (a footprint over distance)
};

}  // namespace lc::render
