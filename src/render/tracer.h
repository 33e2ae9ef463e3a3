// The Whitted tracer: a camera ray's radiance by recursion (Phong shading, direct light from
// a LightEvaluator, reflection and refraction), the shadow rays it sends, and a pixel's
// camera rays. One file, so that the tile loop (renderer.cpp), the reconstruction tiles,
// adaptive antialiasing and the reference pixels all trace a pixel the same way.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/rng.h"
#include "lightcuts/evaluator.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace lc::render {

// Shadow rays from one shading point, offset off the surface toward the light and stopped
// just short of it (a light on a surface is never blocked by that surface).
//
// With `stats`, one ray in kTimedRayOdds (drawn at random: a fixed stride would time the
// same lights at every point) is timed, for --stats' time_shadow_rays_s: three clock reads
// cost ~60 ns, a ray 100-500 ns (at 1 in 16 the reads were 1.6% of a 100k-light room's
// render, perf; at 1 in 64, a million-ray render still times ~15,000). A timed ray over kMaxTimedRayNs was preempted (the
// machine is shared) and is left out of the sample.
class ShadowRays final : public lightcuts::Visibility {
 public:
  static constexpr uint32_t kTimedRayOdds = 64;
  static constexpr int64_t kMaxTimedRayNs = 50'000;
  ShadowRays(const scene::Scene& s, const scene::Hit& h, lightcuts::EvalStats* stats = nullptr)
      : scene_(s), p_(h.p), ng_(h.ng), eps_(s.epsilon()), stats_(stats),
        ownShape_(h.shape >= 0 && h.frontFace && s.isConvex(h.shape) ? h.shape : -1) {}
  Color operator()(const Vec3& wi, float dist) override;
  Color trace(const Vec3& wi, float dist, int& blocker, float& tHit) override;
  bool boxClear(const Vec3& lo, const Vec3& hi, uint32_t& hint) override;
  bool blockerBox(int blocker, Vec3& lo, Vec3& hi) const override;
  int blocksAll(int blocker, const Vec3* dirs, int n, float tMax) const override;
  // The flat face (scene::PlanarFaces) a blocker number names, or -1 (a shape's number).
  int faceOf(int blocker) const {
    const size_t shapes = scene_.shapes().size();
    return blocker >= 0 && size_t(blocker) >= shapes && size_t(blocker) - shapes < scene_.planarFaces().size()
               ? int(size_t(blocker) - shapes)
               : -1;
  }
  // Whether a blocker number names a convex shape.
  bool convexShape(int blocker) const {
    return blocker >= 0 && size_t(blocker) < scene_.shapes().size() && scene_.isConvex(blocker);
  }

 private:
  Vec3 origin(const Vec3& wi, float dist, float& tmax, Vec3& dir) const;
  template <class F>
  Color timed(const F& f);

  const scene::Scene& scene_;
  Vec3 p_, ng_;
  float eps_;
  lightcuts::EvalStats* stats_;
  int ownShape_;  // the convex shape the point lies on, hit from outside (-1: none)
};

// What lights a primary hit (depth 0) in place of a full evaluation: under reconstruction
// cuts, a sample records its lightcut there and a point between samples borrows theirs
// (PrimaryHook, reconstruction_tiles.h).
class PrimaryLight {
 public:
  virtual lightcuts::EvalResult light(const scene::Hit& h, const lightcuts::ShadingPoint& sp,
                                      lightcuts::Visibility& vis, lightcuts::EvalStats& stats) = 0;

 protected:
  ~PrimaryLight() = default;
};

struct Tracer {
  const scene::Scene& scene;
  const lightcuts::LightEvaluator& evaluator;
  int maxDepth;
  lightcuts::EvalStats& stats;
  PrimaryLight* hook = nullptr;
  uint64_t secondaryRays = 0;
  uint64_t cutNodes = 0;  // summed over the shading points of the current sample
  // What its cuts are held to, from RenderOptions (cutSettingsFrom): every tracer of a
  // render's points, pixel centres and sub-samples alike, takes them there.
  float errorFloor = 0;    // RenderOptions::errorFloor, resolved (a pixel's luminance)
  float minError = 0;      // RenderOptions::minError
  bool clearTests = true;  // RenderOptions::clearTests
  void cutSettingsFrom(const RenderOptions& o);

  // One shading point in kTimedPointOdds, drawn at random, is timed in the thread's CPU
  // time (a system call: timing every point would cost a few per cent of a reconstructed
  // point), for --stats' time_lighting_s, what the shadow rays' time is a share of; CPU
  // time, so that a preempted thread counts nothing.
  static constexpr uint32_t kTimedPointOdds = 16;

  // weight: the luminance of the product of kr and kt that carries this ray's light to
  // the pixel (what the error floor is divided by).
  Color trace(const scene::Ray& ray, int depth, float weight = 1);

 private:
  lightcuts::EvalResult directLight(const scene::Hit& h, const lightcuts::ShadingPoint& sp, int depth);
  lightcuts::EvalResult evaluateLight(const scene::Hit& h, const lightcuts::ShadingPoint& sp, int depth);
};

// Radiance along one camera ray (exposed for tests).
Color traceRay(const scene::Scene& scene, const lightcuts::LightEvaluator& evaluator, const scene::Ray& ray,
               int maxDepth, lightcuts::EvalStats& stats);

struct PixelResult {
  Color color;
  float cut = 0;
  float shadowRays = 0;  // per sample
};

// The spp sample positions of a pixel in [0, 1)^2, from its random stream: multi-jittered
// (core/multi_jitter.h) on the squarest grid of spp cells; one sample is the centre.
void pixelSamplePositions(int spp, Rng& rng, std::vector<Vec2>& out);

// Pixel (x, y): o.spp camera rays from the pixel's own random stream (pixelSamplePositions), their mean radiance, cut nodes and shadow rays.
// The rays are counted in primary and secondary; `hook` lights the primary hits.
PixelResult renderPixel(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o, int x,
                        int y, lightcuts::EvalStats& stats, uint64_t& primary, uint64_t& secondary,
                        PrimaryLight* hook = nullptr);

// The pixel into the result's image and per-pixel buffers, marked done.
void storePixel(RenderResult& res, int width, int x, int y, const PixelResult& p);

// What one thread counts over the tiles it renders, added into RenderStats at the end.
struct TileCounters {
  lightcuts::EvalStats stats;
  uint64_t primary = 0, secondary = 0;  // camera rays; reflection and refraction rays
  uint64_t samples = 0;                 // full lightcuts recorded as reconstruction samples
  uint64_t fallbacks = 0;               // primary hits no sample could serve: full lightcuts
  uint64_t coarseCells = 0;             // coarse reconstruction cells kept whole
  uint64_t splitCells = 0;              // cells of the spacing or less split for disagreement
  uint64_t refinedCells = 0;            // cells split for a refuting group probe
  uint64_t tiles = 0, pixels = 0;
  uint64_t aaPixels = 0, aaSubSamples = 0;  // adaptive antialiasing's pixels and their rays
};

}  // namespace lc::render
