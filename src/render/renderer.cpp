#include "render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <climits>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

#include <time.h>

#include "core/rng.h"
#include "render/adaptive.h"

namespace lc::render {

namespace {

using lightcuts::EvalStats;
using lightcuts::LightEvaluator;
using lightcuts::ShadingPoint;
using scene::Hit;
using scene::Ray;
using scene::Scene;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

uint64_t threadCpuNanos() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return uint64_t(ts.tv_sec) * 1'000'000'000u + uint64_t(ts.tv_nsec);
}

// Shadow rays from one shading point, offset off the surface toward the light and stopped
// just short of it (a light on a surface is never blocked by that surface).
//
// With `stats`, one ray in kTimedRayOdds (drawn at random: a fixed stride would time the
// same lights at every point) is timed, for --stats' time_shadow_rays_s: three clock reads
// cost ~60 ns, a ray 100-500 ns. A timed ray over kMaxTimedRayNs was preempted (the
// machine is shared) and is left out of the sample.
class ShadowRays final : public lightcuts::Visibility {
 public:
  static constexpr uint32_t kTimedRayOdds = 16;
  static constexpr int64_t kMaxTimedRayNs = 50'000;
  ShadowRays(const Scene& s, const Hit& h, EvalStats* stats = nullptr)
      : scene_(s), p_(h.p), ng_(h.ng), eps_(s.epsilon()), stats_(stats) {}
  Color operator()(const Vec3& wi, float dist) override {
    return timed([&] {
      float tmax;
      Vec3 o = origin(wi, dist, tmax);
      if (!(tmax > 0)) return Color(1);
      return scene_.transmittance(o, wi, tmax);
    });
  }
  Color trace(const Vec3& wi, float dist, int& blocker, float& tHit) override {
    return timed([&] {
      float tmax;
      Vec3 o = origin(wi, dist, tmax);
      blocker = kVisible;
      tHit = 0;
      if (!(tmax > 0)) return Color(1);
      int shape = scene_.firstHit(o, wi, tmax, tHit);
      if (shape < 0) return Color(1);
      if (scene_.isTransmissive(shape)) {  // glass on the way: the walk through it decides
        Color v = scene_.transmittance(o, wi, tmax);
        blocker = isBlack(v) ? kUnknownBlocker : kVisible;
        return v;
      }
      blocker = scene_.isConvex(shape) ? shape : kUnknownBlocker;
      return Color(0);
    });
  }

 private:
  // The ray's origin, off the surface on the light's side and a step toward the light,
  // and its length to just short of the light. The step matters on an edge where two
  // surfaces meet (a room's corner): the point lies in the other surface's plane, and
  // watertight hits (issue 29) would count that surface at t = 0 and shadow the edge.
  Vec3 origin(const Vec3& wi, float dist, float& tmax) const {
    tmax = std::isinf(dist) ? kInf : dist - 3 * eps_;
    return p_ + ng_ * (dot(wi, ng_) >= 0 ? eps_ : -eps_) + wi * eps_;
  }

  template <class F>
  Color timed(const F& f) {
    if (!stats_) return f();
    ++stats_->tracedRays;
    static thread_local uint64_t state = 0x9e3779b97f4a7c15ull;
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;  // xorshift64
    if (state % kTimedRayOdds != 0) return f();
    // t1 - t0 is one clock read: taken off the ray's interval, which holds one too.
    auto t0 = Clock::now(), t1 = Clock::now();
    Color c = f();
    auto t2 = Clock::now();
    const int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>((t2 - t1) - (t1 - t0)).count();
    if (ns <= kMaxTimedRayNs) {
      ++stats_->timedRays;
      stats_->timedRayNanos += uint64_t(std::max<int64_t>(ns, 0));
    }
    return c;
  }

  const Scene& scene_;
  Vec3 p_, ng_;
  float eps_;
  EvalStats* stats_;
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

bool sameSurface(int shapeA, const Vec3& pa, const Vec3& na, int shapeB, const Vec3& pb, const Vec3& nb) {
  if (shapeA != shapeB || dot(na, nb) < kSampleMinCos) return false;
  Vec3 d = pb - pa;
  return std::fabs(dot(na, d)) <= kSampleMaxPlaneSlope * length(d) &&
         std::fabs(dot(nb, d)) <= kSampleMaxPlaneSlope * length(d);
}

// The merged cuts of one cell of pixels, one per subset of its corner samples, made when
// first needed.
struct CellCuts {
  lightcuts::MergedCut merged[16];
  bool ready[16] = {};
  // Antialiasing's sub-samples: the samples the merged cuts are of (count -1: unknown).
  int aaCount = -1;
  const CutSample* aaSamples[4] = {};
  void reset() {
    std::fill(std::begin(ready), std::end(ready), false);
    aaCount = -1;
  }
};

// What happens at a primary hit (depth 0) under reconstruction cuts.
struct PrimaryHook {
  CutSample* record = nullptr;                 // record the lightcut here, or
  const CutSample* const* samples = nullptr;   // rebuild the cut from these (distinct)
  int count = 0;
  CellCuts* cell = nullptr;
  Vec3 eye;                   // the camera's position and
  float maxSeparation = kInf;  // how far a sample may be, over the point's distance to it
  int px = 0, py = 0;         // the pixel, and
  int cx[4] = {}, cy[4] = {};  // the samples' pixels
  bool preselected = false;  // samples chosen for this very hit (antialiasing): no hull test
  uint64_t fallbacks = 0;  // hits no sample could serve: they got a full lightcut
};

// Whether pixel (x, y) lies in the convex hull of the samples in `mask`: a point borrows
// only between samples on its surface, never beyond them. (Toward an edge a point may be
// nearer lights than any sample was, and need a finer cut.) Integer, so exact.
bool insideSamples(const PrimaryHook& h, unsigned mask) {
  int idx[4], k = 0;
  for (int i = 0; i < h.count; ++i)
    if (mask >> i & 1) idx[k++] = i;
  auto cross = [&](int a, int b) {  // (b - a) x (p - a)
    return int64_t(h.cx[b] - h.cx[a]) * (h.py - h.cy[a]) - int64_t(h.cy[b] - h.cy[a]) * (h.px - h.cx[a]);
  };
  auto between = [&](int a, int b) {
    return cross(a, b) == 0 && std::min(h.cx[a], h.cx[b]) <= h.px && h.px <= std::max(h.cx[a], h.cx[b]) &&
           std::min(h.cy[a], h.cy[b]) <= h.py && h.py <= std::max(h.cy[a], h.cy[b]);
  };
  switch (k) {
    case 1: return h.px == h.cx[idx[0]] && h.py == h.cy[idx[0]];
    case 2: return between(idx[0], idx[1]);
    case 3: {
      int64_t a = cross(idx[0], idx[1]), b = cross(idx[1], idx[2]), c = cross(idx[2], idx[0]);
      bool neg = a < 0 || b < 0 || c < 0, pos = a > 0 || b > 0 || c > 0;
      if (a == 0 && b == 0 && c == 0)  // collinear corners of a collapsed cell
        return between(idx[0], idx[1]) || between(idx[1], idx[2]) || between(idx[0], idx[2]);
      return !(neg && pos);
    }
    case 4: return true;  // the whole cell
    default: return false;
  }
}

// The samples a hit on `shape` with normal n may borrow from: only those on its surface
// (across an edge, visibility borrowed from the other side would be wrong).
unsigned matchingSamples(const PrimaryHook& h, int shape, const Vec3& p, const Vec3& n) {
  unsigned mask = 0;
  float far2 = length2(p - h.eye) * h.maxSeparation * h.maxSeparation;
  for (int i = 0; i < h.count; ++i) {
    const CutSample& s = *h.samples[i];
    if (s.cut.valid && sameSurface(shape, p, n, s.shape, s.p, s.n) && length2(s.p - p) <= far2) mask |= 1u << i;
  }
  return mask;
}

// The samples that serve a hit, or 0 when none can: those on its surface, if the hit lies
// between them.
unsigned servingSamples(const PrimaryHook& h, int shape, const Vec3& p, const Vec3& n) {
  unsigned mask = matchingSamples(h, shape, p, n);
  return mask != 0 && (h.preselected || insideSamples(h, mask)) ? mask : 0;
}

struct Tracer {
  const Scene& scene;
  const LightEvaluator& evaluator;
  int maxDepth;
  EvalStats& stats;
  PrimaryHook* hook = nullptr;
  uint64_t secondaryRays = 0;
  uint64_t cutNodes = 0;  // summed over the shading points of the current sample
  float errorFloor = 0;   // RenderOptions::errorFloor, resolved (a pixel's luminance)

  // The light at a shading point. One point in kTimedPointOdds, drawn at random, is timed
  // in the thread's CPU time (a system call: timing every point would cost a few per cent
  // of a reconstructed point), for --stats' time_lighting_s, what the shadow rays' time is
  // a share of; CPU time, so that a preempted thread counts nothing.
  static constexpr uint32_t kTimedPointOdds = 16;
  lightcuts::EvalResult directLight(const Hit& h, const ShadingPoint& sp, int depth) {
    ++stats.litPoints;
    static thread_local uint64_t state = 0x2545f4914f6cdd1dull;
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;  // xorshift64
    if (state % kTimedPointOdds != 0) return evaluateLight(h, sp, depth);
    const uint64_t t0 = threadCpuNanos();
    lightcuts::EvalResult r = evaluateLight(h, sp, depth);
    stats.lightingNanos += threadCpuNanos() - t0;
    ++stats.timedPoints;
    return r;
  }
  lightcuts::EvalResult evaluateLight(const Hit& h, const ShadingPoint& sp, int depth) {
    ShadowRays vis(scene, h, &stats);
    if (depth > 0 || !hook) return evaluator.evaluate(sp, vis, stats);
    if (hook->record) {
      hook->record->shape = h.shape;
      hook->record->p = h.p;
      hook->record->n = h.ns;
      return evaluator.evaluateRecorded(sp, vis, stats, hook->record->cut);
    }
    const lightcuts::CutRecord* cuts[4];
    int k = 0;
    unsigned mask = servingSamples(*hook, h.shape, h.p, h.ns);
    for (int i = 0; i < hook->count; ++i)
      if (mask >> i & 1) cuts[k++] = &hook->samples[i]->cut;
    if (k == 0) {
      ++hook->fallbacks;
      return evaluator.evaluate(sp, vis, stats);
    }
    if (!hook->cell->ready[mask]) {
      evaluator.mergeSamples(cuts, k, hook->cell->merged[mask]);
      hook->cell->ready[mask] = true;
    }
    return evaluator.reconstruct(sp, vis, stats, hook->cell->merged[mask]);
  }

  // weight: the luminance of the product of kr and kt that carries this ray's light to
  // the pixel (what the error floor is divided by).
  Color trace(const Ray& ray, int depth, float weight = 1) {
    Hit h;
    // A ray that escapes sees the environment (camera, reflected and refracted rays alike).
    if (!scene.intersect(ray, h)) return scene.background(normalize(ray.d));
    scene::ShadingMaterial m = scene.shadingMaterial(h);
    Color L = m.ke + m.ka * scene.ambient();
    Vec3 v = -normalize(ray.d);
    if (!isBlack(m.kd) || !isBlack(m.ks)) {
      ShadingPoint sp;
      sp.p = h.p;
      sp.n = h.ns;
      sp.r = normalize(reflect(v, h.ns));
      sp.kd = m.kd;
      sp.ks = m.ks;
      sp.shininess = m.shininess;
      sp.errorFloor = errorFloor > 0 && weight > 0 ? errorFloor / weight : 0;
      lightcuts::EvalResult r = directLight(h, sp, depth);
      L += r.radiance;
      cutNodes += r.cutSize;
    }
    if (depth >= maxDepth) return L;
    if (!isBlack(m.kr)) {
      Vec3 r = normalize(reflect(v, h.ns));
      // A non-finite direction (NaN normal, extreme values) is dropped, not traced.
      if (isFinite(r)) {
        ++secondaryRays;
        L += m.kr * trace(Ray{scene.offsetOrigin(h, r), r, 0, kInf}, depth + 1, weight * luminance(m.kr));
      }
    }
    if (!isBlack(m.kt)) {
      // Entering through the front face goes from air (index 1) into the material.
      float eta = h.frontFace ? 1.0f / m.ior : m.ior;
      float cosI = std::min(1.0f, dot(v, h.ns));
      float sin2T = eta * eta * (1 - cosI * cosI);
      Vec3 t;
      // (written so that a NaN sin2T, e.g. inf * 0 for a huge index, is total reflection)
      if (!(sin2T < 1)) {
        t = normalize(reflect(v, h.ns));  // total internal reflection
      } else {
        t = normalize(-v * eta + h.ns * (eta * cosI - std::sqrt(1 - sin2T)));
      }
      // A refracted ray with a non-finite direction is dropped, not traced.
      if (isFinite(t)) {
        ++secondaryRays;
        L += m.kt * trace(Ray{scene.offsetOrigin(h, t), t, 0, kInf}, depth + 1, weight * luminance(m.kt));
      }
    }
    return L;
  }
};

// Sample s of spp inside a pixel: stratified on a near-square grid, jittered; a single
// sample takes the pixel centre.
Vec2 samplePosition(int s, int spp, Rng& rng) {
  if (spp <= 1) return Vec2(0.5f, 0.5f);
  int gx = int(std::ceil(std::sqrt(double(spp))));
  int gy = (spp + gx - 1) / gx;
  int ix = s % gx, iy = s / gx;
  return Vec2((float(ix) + rng.uniform()) / float(gx), (float(iy) + rng.uniform()) / float(gy));
}

struct PixelResult {
  Color color;
  float cut = 0;
  float shadowRays = 0;  // per sample
};

PixelResult renderPixel(const Scene& scene, const LightEvaluator& ev, const RenderOptions& o, int x, int y,
                        EvalStats& stats, uint64_t& primary, uint64_t& secondary, PrimaryHook* hook = nullptr) {
  Rng rng(o.seed, uint64_t(y) * uint64_t(o.width) + uint64_t(x));
  const uint64_t rays0 = stats.shadowRays;
  Tracer tr{scene, ev, o.maxDepth, stats, hook};
  tr.errorFloor = std::max(0.0f, o.errorFloor);
  Color sum(0);
  const scene::Camera& cam = scene.camera();
  for (int s = 0; s < o.spp; ++s) {
    Vec2 u = samplePosition(s, o.spp, rng);
    float sx = (float(x) + u.x) / float(o.width), sy = (float(y) + u.y) / float(o.height);
    Ray ray{cam.eye, normalize(cam.direction(sx, sy)), 0, kInf};
    ++primary;
    Color c = tr.trace(ray, 0);
    if (!isFinite(c)) c = Color(0);  // never let a NaN reach the image
    sum += c;
  }
  secondary += tr.secondaryRays;
  return {sum / float(o.spp), float(tr.cutNodes) / float(o.spp), float(stats.shadowRays - rays0) / float(o.spp)};
}

void storePixel(RenderResult& res, int width, int x, int y, const PixelResult& p) {
  size_t i = size_t(y) * size_t(width) + size_t(x);
  res.image.pixels[i] = p.color;
  res.cutSize[i] = p.cut;
  res.shadowRays[i] = p.shadowRays;
  res.done[i] = 1;
}

// Samples on the lines where tiles meet, shared by the tiles on both sides: the first
// tile to need one computes it, the other reads it. A tile that finds one being computed
// computes its own copy (the same values: a sample depends only on its pixel), so no
// thread waits on another. Each entry counts the tiles that may use it (two, four where
// four tiles meet); when the last of them is done the sample's cut is freed, so only the
// lines along unfinished tiles hold memory.
class EdgeSamples {
 public:
  EdgeSamples(int width, int height, int tile)
      : width_(width), height_(height), tile_(tile),
        linesX_(std::max(0, (width - 1) / tile)), linesY_(std::max(0, (height - 1) / tile)),
        entries_(size_t(linesX_) * size_t(height) + size_t(linesY_) * size_t(width)) {
    // A pixel on a vertical line is used by the tiles left and right of it, and, when it
    // is on a horizontal line too, by those above and below them.
    for (int k = 1; k <= linesX_; ++k)
      for (int y = 0; y < height_; ++y) at(k * tile_, y)->users = onLineY(y) ? 4 : 2;
    for (int m = 1; m <= linesY_; ++m)
      for (int x = 0; x < width_; ++x)
        if (!onLineX(x)) at(x, m * tile_)->users = 2;
  }

  struct Entry {
    std::atomic<uint8_t> state{0};  // kEmpty, kBusy or kReady
    std::atomic<uint8_t> users{0};  // tiles that may still read it
    CutSample sample;
    PixelResult pixel;
  };
  static constexpr uint8_t kEmpty = 0, kBusy = 1, kReady = 2;

  // The entry of pixel (x, y) if it lies on a line between tiles, else null.
  Entry* at(int x, int y) {
    if (onLineX(x)) return &entries_[size_t(x / tile_ - 1) * size_t(height_) + size_t(y)];
    if (onLineY(y))
      return &entries_[size_t(linesX_) * size_t(height_) + size_t(y / tile_ - 1) * size_t(width_) + size_t(x)];
    return nullptr;
  }

  // The tile of pixels [x0, x1) x [y0, y1) is done: it reads none of the samples on its
  // border again (its cells' corners reach x1 and y1, clipped to the image).
  void tileDone(int x0, int y0, int x1, int y1) {
    const int xe = std::min(x1, width_ - 1), ye = std::min(y1, height_ - 1);
    auto release = [&](int x, int y) {
      Entry* e = at(x, y);
      if (e && e->users.fetch_sub(1, std::memory_order_acq_rel) == 1) e->sample.cut = lightcuts::CutRecord{};
    };
    for (int x = x0; x <= xe; ++x) {
      release(x, y0);
      if (ye != y0) release(x, ye);
    }
    for (int y = y0 + 1; y < ye; ++y) {
      release(x0, y);
      if (xe != x0) release(xe, y);
    }
  }

 private:
  bool onLineX(int x) const { return x > 0 && x % tile_ == 0 && x / tile_ <= linesX_; }
  bool onLineY(int y) const { return y > 0 && y % tile_ == 0 && y / tile_ <= linesY_; }

  int width_, height_, tile_, linesX_, linesY_;
  std::vector<Entry> entries_;
};

// One tile under reconstruction cuts. The tile is cut into cells of S x S pixels with
// samples (full lightcuts through pixel centres) on their corners. A pixel whose hit lies
// inside the samples on its surface (servingSamples) is rebuilt from them; where some are
// not, the cell splits in four, with new samples on the corners of the parts, down to
// single pixels: samples gather along edges and silhouettes, smooth regions share a few
// (the adaptive image sampling of Walter et al. 2005, sec. 5). Every choice depends only
// on the hits, so the image does not depend on the order tiles run in. Corners on the
// tile's right and bottom edges belong to the next tiles; they are shared with them
// (EdgeSamples) and stored by the tile they belong to.
struct ReconstructionTile {
  const Scene& scene;
  const LightEvaluator& ev;
  const RenderOptions& o;
  const RenderOptions& centre;  // o with one sample per pixel
  EvalStats& stats;
  uint64_t &primary, &secondary, &samples, &fallbacks, &coarseCells;
  std::vector<CutSample>& slots;
  std::vector<uint8_t>& state;  // per slot: kDone when its pixel is stored
  std::vector<const CutSample*>& shared;  // per slot: its sample (the slot's, or an EdgeSamples one), once made
  CellCuts& cell;
  RenderResult& res;
  EdgeSamples& edges;
  int x0, y0, x1, y1;  // the tile's pixels: [x0, x1) x [y0, y1)

  static constexpr uint8_t kDone = 1;

  size_t slot(int x, int y) const { return size_t(y - y0) * size_t(x1 - x0 + 1) + size_t(x - x0); }

  const CutSample& sample(int x, int y) {
    size_t i = slot(x, y);
    CutSample& cs = slots[i];
    if (shared[i]) return *shared[i];
    // On a line between tiles: read the sample if the tile on the other side made it,
    // else make it there for both.
    EdgeSamples::Entry* e = edges.at(x, y);
    uint8_t expected = EdgeSamples::kEmpty;
    const bool readOnly = e && e->state.load(std::memory_order_acquire) == EdgeSamples::kReady;
    const bool publish = e && !readOnly && e->state.compare_exchange_strong(expected, EdgeSamples::kBusy,
                                                                            std::memory_order_acq_rel);
    CutSample& target = readOnly || publish ? e->sample : cs;
    PixelResult p;
    if (readOnly) {
      p = e->pixel;
    } else {
      target.cut.clear();
      target.shape = -1;
      PrimaryHook hook;
      hook.record = &target;
      p = renderPixel(scene, ev, centre, x, y, stats, primary, secondary, &hook);
      ++samples;
      if (publish) {
        e->pixel = p;
        e->state.store(EdgeSamples::kReady, std::memory_order_release);
      }
    }
    shared[i] = &target;
    // With one sample per pixel the sample is the pixel; otherwise the pixel is rendered
    // from its samples like any other.
    if (o.spp == 1 && x < x1 && y < y1) {
      storePixel(res, o.width, x, y, p);
      state[i] |= kDone;
    }
    return target;
  }

  float maxSeparation = kInf;  // the footprint limit of cells of S pixels
  int spacing = 0;  // S: cells larger than this are coarse (kept whole only if they agree)

  // Cells of C x C pixels (C = S, or the coarse spacing) over the tile.
  void run(int S, int C) {
    const scene::Camera& cam = scene.camera();
    Vec3 a = normalize(cam.direction(0.5f, 0.5f)), b = normalize(cam.direction(0.5f + 1.0f / float(o.width), 0.5f));
    maxSeparation = kSampleMaxFootprints * float(S) * length(a - b);
    spacing = S;
    size_t n = size_t(x1 - x0 + 1) * size_t(y1 - y0 + 1);
    if (slots.size() < n) slots.resize(n);
    state.assign(n, 0);
    shared.assign(n, nullptr);
    for (int cy = y0; cy < y1; cy += C)
      for (int cx = x0; cx < x1; cx += C) cellPixels(cx, cy, std::min(C, x1 - cx), std::min(C, y1 - cy));
  }

  // Whether a coarse cell may be rebuilt whole: four corners on one surface, the nodes they
  // disagree about holding at most kCoarseMaxDisagreement of their merged cut's light (the
  // merged cut is made here and kept for the cell's pixels).
  bool coarseAgrees(const CutSample* const* corners, int n) {
    if (n != 4) return false;
    for (int i = 0; i < 4; ++i) {
      if (!corners[i]->cut.valid) return false;
      for (int j = i + 1; j < 4; ++j)
        if (!sameSurface(corners[i]->shape, corners[i]->p, corners[i]->n, corners[j]->shape, corners[j]->p,
                         corners[j]->n))
          return false;
    }
    const lightcuts::CutRecord* cuts[4];
    for (int i = 0; i < 4; ++i) cuts[i] = &corners[i]->cut;
    lightcuts::MergedCut& merged = cell.merged[15];
    ev.mergeSamples(cuts, 4, merged);
    cell.ready[15] = true;
    return lightcuts::disagreementShare(scene.lights(), merged, corners[0]->p, corners[0]->n) <= kCoarseMaxDisagreement;
  }

  // The surface a pixel centre's ray shades (false: none).
  bool probe(int x, int y, int& shape, Vec3& p, Vec3& n) const {
    const scene::Camera& cam = scene.camera();
    Ray ray{cam.eye, normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height))), 0,
            kInf};
    Hit h;
    if (!scene.intersect(ray, h)) return false;
    scene::ShadingMaterial m = scene.shadingMaterial(h);
    if (isBlack(m.kd) && isBlack(m.ks)) return false;
    shape = h.shape;
    p = h.p;
    n = h.ns;
    return true;
  }

  // The pixels [cx, cx + w) x [cy, cy + h) still pending; corners at cx + w and cy + h
  // (clipped to the image: a last cell's far corner is its own last pixel).
  void cellPixels(int cx, int cy, int w, int h) {
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
    bool any = false;
    for (int y = cy; y < cy + h && !any; ++y)
      for (int x = cx; x < cx + w && !any; ++x) any = !(state[slot(x, y)] & kDone);
    if (!any) return;
    const int xa = cx, xb = std::min(cx + w, o.width - 1), ya = cy, yb = std::min(cy + h, o.height - 1);
    const CutSample* corners[4];
    PrimaryHook hook;
    int n = 0;
    auto corner = [&](int x, int y) {
      corners[n] = &sample(x, y);
      hook.cx[n] = x;
      hook.cy[n] = y;
      ++n;
    };
    corner(xa, ya);
    if (xb != xa) corner(xb, ya);
    if (yb != ya) corner(xa, yb);
    if (xb != xa && yb != ya) corner(xb, yb);
    cell.reset();
    hook.samples = corners;
    hook.count = n;
    hook.cell = &cell;
    hook.eye = scene.camera().eye;
    const bool coarse = w > spacing || h > spacing;
    // The footprint limit grows with the cell (a coarse cell's points lie farther from
    // its corners), so on a surface seen face on the cell stays whole.
    hook.maxSeparation = coarse ? maxSeparation * float(std::max(w, h)) / float(spacing) : maxSeparation;
    const bool split = coarse && !coarseAgrees(corners, n);  // at once: its pixels wait for finer cells
    bool left = split;  // pixels this cell's samples cannot serve
    coarseCells += coarse && !split;
    for (int y = cy; y < cy + h && !split; ++y)
      for (int x = cx; x < cx + w; ++x) {
        uint8_t& st = state[slot(x, y)];
        if (st & kDone) continue;
        if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
        hook.px = x;
        hook.py = y;
        int shape = -1;
        Vec3 pos, nrm;
        // A pixel with no surface to shade, or one its samples serve, is done here; the
        // rest wait for smaller cells (a single pixel is its own sample).
        if (probe(x, y, shape, pos, nrm) && !servingSamples(hook, shape, pos, nrm) && (w > 1 || h > 1)) {
          left = true;
          continue;
        }
        hook.fallbacks = 0;
        storePixel(res, o.width, x, y, renderPixel(scene, ev, o, x, y, stats, primary, secondary, &hook));
        fallbacks += hook.fallbacks;
        st |= kDone;
      }
    if (!left) return;
    int w0 = w > 1 ? w / 2 : w, h0 = h > 1 ? h / 2 : h;
    cellPixels(cx, cy, w0, h0);
    if (w > w0) cellPixels(cx + w0, cy, w - w0, h0);
    if (h > h0) cellPixels(cx, cy + h0, w0, h - h0);
    if (w > w0 && h > h0) cellPixels(cx + w0, cy + h0, w - w0, h - h0);
  }
};

// Adaptive antialiasing (RenderOptions::aa, render/adaptive.h). What a pixel's sub-samples
// add: their radiance, cut nodes and shadow rays, summed.
// The merged cuts of the last few sets of samples sub-samples borrowed from (neighbouring
// sub-samples, and pixels, mostly borrow from the same ones), replaced in turn.
struct AaCutCache {
  static constexpr int kEntries = 8;
  CellCuts entries[kEntries];
  int next = 0;
  void reset() {
    for (CellCuts& e : entries) e.reset();
    next = 0;
  }
  CellCuts* find(const CutSample* const* set, int k) {
    for (CellCuts& e : entries)
      if (e.aaCount == k && std::equal(set, set + k, e.aaSamples)) return &e;
    CellCuts& e = entries[next];
    next = (next + 1) % kEntries;
    e.reset();
    e.aaCount = k;
    std::copy(set, set + k, e.aaSamples);
    return &e;
  }
};

struct SubSampleSums {
  Color color{0};
  double cut = 0, shadowRays = 0;
  int count = 0;
  uint64_t fallbacks = 0;  // sub-samples no reconstruction sample could serve
};

// The sub-samples of pixel (x, y) on the g x g grid. Under reconstruction cuts (rt), each
// borrows from the tile's samples on its surface: the nearest one in each quadrant around
// the sub-sample's own position within two cells, used when the sub-sample lies between
// them (tested at 1/16 pixel) or one of them is a neighbouring pixel (samples gather along
// edges, where a sub-sample may hit the surface beyond); else it gets a full lightcut.
// (Quadrants around the pixel instead let the pixel's own sample, where it is one, win all
// four, and sub-samples on a contact line borrowed from it alone: up to 13% off.)
SubSampleSums traceSubSamples(const Scene& scene, const LightEvaluator& ev, const RenderOptions& o, int x, int y,
                              int g, EvalStats& stats, uint64_t& primary, uint64_t& secondary,
                              const ReconstructionTile* rt, AaCutCache* cache) {
  SubSampleSums sums;
  Rng rng(o.seed, aaStream(x, y, o.width, o.height));
  const scene::Camera& cam = scene.camera();
  for (int s = 0; s < g * g - 1; ++s) {
    Vec2 u = aaSubSamplePosition(s, g, rng);
    Ray ray{cam.eye, normalize(cam.direction((float(x) + u.x) / float(o.width), (float(y) + u.y) / float(o.height))), 0,
            kInf};
    PrimaryHook hook;
    const CutSample* chosen[4];
    if (rt) {
      hook.samples = chosen;
      hook.eye = cam.eye;
      hook.maxSeparation = rt->maxSeparation;
      // Hull tests at the sub-sample's own position, in 1/kSub pixel units (sample pixels
      // at their centres).
      constexpr int kSub = 16;
      hook.px = x * kSub + std::min(kSub - 1, int(u.x * float(kSub)));
      hook.py = y * kSub + std::min(kSub - 1, int(u.y * float(kSub)));
      hook.preselected = true;
      Hit hit;
      if (scene.intersect(ray, hit)) {
        const float far2 = length2(hit.p - cam.eye) * rt->maxSeparation * rt->maxSeparation;
        const int R = 2 * std::max(1, rt->spacing);
        int bd[4] = {INT32_MAX, INT32_MAX, INT32_MAX, INT32_MAX}, bx[4] = {}, by[4] = {};
        const CutSample* best[4] = {};
        for (int Y = std::max(rt->y0, y - R); Y <= std::min({rt->y1, y + R, o.height - 1}); ++Y)
          for (int X = std::max(rt->x0, x - R); X <= std::min({rt->x1, x + R, o.width - 1}); ++X) {
            const CutSample* cs = rt->shared[rt->slot(X, Y)];
            if (!cs || !cs->cut.valid || !sameSurface(hit.shape, hit.p, hit.ns, cs->shape, cs->p, cs->n) ||
                length2(cs->p - hit.p) > far2)
              continue;
            // Quadrants and distances around the sub-sample's own position.
            const int dx = X * kSub + kSub / 2 - hook.px, dy = Y * kSub + kSub / 2 - hook.py, d = dx * dx + dy * dy;
            for (int q = 0; q < 4; ++q)
              if (((q & 1) ? dx >= 0 : dx <= 0) && ((q & 2) ? dy >= 0 : dy <= 0) && d < bd[q]) {
                bd[q] = d;
                best[q] = cs;
                bx[q] = X;
                by[q] = Y;
              }
          }
        // Distinct, in image order (one set, one order: its merged cuts are cached).
        int order[4], n = 0;
        for (int q = 0; q < 4; ++q) {
          bool dup = !best[q];
          for (int j = 0; j < n && !dup; ++j) dup = best[order[j]] == best[q];
          if (!dup) order[n++] = q;
        }
        for (int i = 1; i < n; ++i)  // insertion sort by (y, x)
          for (int j = i; j > 0 && (by[order[j]] < by[order[j - 1]] ||
                                    (by[order[j]] == by[order[j - 1]] && bx[order[j]] < bx[order[j - 1]]));
               --j)
            std::swap(order[j], order[j - 1]);
        int k = 0, nearest = INT32_MAX;
        for (int j = 0; j < n; ++j) {
          const int q = order[j];
          chosen[k] = best[q];
          hook.cx[k] = bx[q] * kSub + kSub / 2;
          hook.cy[k] = by[q] * kSub + kSub / 2;
          nearest = std::min(nearest, std::max(std::abs(bx[q] - x), std::abs(by[q] - y)));
          ++k;
        }
        hook.count = k;
        if (k > 0 && !(nearest <= 1 || insideSamples(hook, (1u << k) - 1))) hook.count = 0;
      }
      hook.cell = cache->find(chosen, hook.count);
    }
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

// The tile [x0, x1) x [y0, y1) after its centre samples: flags the pixels whose centres
// disagree with a neighbour's and re-samples them. Every input is the tile's own (its
// pixels, its samples, centre rays probed around it), so the result does not depend on
// the order tiles run in.
void adaptiveTile(const Scene& scene, const LightEvaluator& ev, const RenderOptions& o, RenderResult& res,
                  EvalStats& stats, uint64_t& primary, uint64_t& secondary, uint64_t& aaPixels, uint64_t& aaSubs,
                  uint64_t& fallbacks, int x0, int y0, int x1, int y1, const ReconstructionTile* rt,
                  AaCutCache* cache) {
  if (o.aa != AntiAliasing::Adaptive || o.spp != 1) return;
  const int g = aaGridSide(o.aaSamples);
  if (g == 0) return;
  if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
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
      Ray ray{cam.eye, normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height))),
              0, kInf};
      Hit hit;
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
      SubSampleSums sub = traceSubSamples(scene, ev, o, x, y, g, stats, primary, secondary, rt, cache);
      size_t i = size_t(y) * size_t(o.width) + size_t(x);
      res.image.pixels[i] = (res.image.pixels[i] + sub.color) / n;
      res.cutSize[i] = float((double(res.cutSize[i]) + sub.cut) / double(n));
      res.shadowRays[i] = float((double(res.shadowRays[i]) + sub.shadowRays) / double(n));
      res.aaFlagged[i] = 1;
      ++aaPixels;
      aaSubs += uint64_t(sub.count);
      fallbacks += sub.fallbacks;
    }
}

// A pixel as the render made it, with another evaluator (brute force for the reference
// pixels, apples to apples): the centre sample, and where antialiasing re-sampled the
// pixel, the same sub-samples (same positions), each with a full evaluation.
Color pixelWithSubSamples(const Scene& scene, const LightEvaluator& ev, const RenderOptions& o, const RenderResult& res,
                          int x, int y, EvalStats& stats) {
  uint64_t a = 0, b = 0;
  Color c = renderPixel(scene, ev, o, x, y, stats, a, b).color;
  if (!res.aaFlagged[size_t(y) * size_t(o.width) + size_t(x)]) return c;
  const int g = aaGridSide(o.aaSamples);
  SubSampleSums sub = traceSubSamples(scene, ev, o, x, y, g, stats, a, b, nullptr, nullptr);
  return (c + sub.color) / float(g * g);
}

// K pixels spread over the image (Halton 2,3), without duplicates.
std::vector<std::pair<int, int>> referencePixelSet(int k, int w, int h) {
  std::vector<std::pair<int, int>> px;
  std::set<std::pair<int, int>> seen;
  for (uint32_t i = 1; int(px.size()) < std::min(k, w * h) && i < uint32_t(k) * 16 + 64; ++i) {
    int x = std::min(w - 1, int(radicalInverse(2, i) * float(w)));
    int y = std::min(h - 1, int(radicalInverse(3, i) * float(h)));
    if (seen.insert({x, y}).second) px.emplace_back(x, y);
  }
  return px;
}

}  // namespace

double vplClampedFraction(const Scene& scene, const RenderOptions& o, int points, uint64_t maxEvaluations) {
  const LightSet& ls = scene.lights();
  std::vector<uint32_t> vpls;
  for (uint32_t i = 0; i < ls.lights.size(); ++i)
    if (ls.groups[ls.lights[i].group].isVpl) vpls.push_back(i);
  if (vpls.empty()) return 0;
  int k = int(std::clamp<uint64_t>(maxEvaluations / vpls.size(), 16, uint64_t(points)));
  auto px = referencePixelSet(k, o.width, o.height);
  std::vector<double> clamped(px.size(), 0), unclamped(px.size(), 0);
  tbb::parallel_for(size_t(0), px.size(), [&](size_t i) {
    const scene::Camera& cam = scene.camera();
    Vec3 d = normalize(cam.direction((float(px[i].first) + 0.5f) / float(o.width),
                                     (float(px[i].second) + 0.5f) / float(o.height)));
    Hit h;
    if (!scene.intersect(Ray{cam.eye, d, 0, kInf}, h)) return;
    scene::ShadingMaterial m = scene.shadingMaterial(h);
    if (isBlack(m.kd)) return;
    ShadingPoint sp;
    sp.p = h.p;
    sp.n = h.ns;
    sp.r = normalize(reflect(-d, h.ns));
    sp.kd = m.kd;
    ShadowRays vis(scene, h);
    for (uint32_t li : vpls) {
      const Light& l = ls.lights[li];
      const LightGroup& g = ls.groups[l.group];
      Color mg;
      Vec3 wi;
      float dist;
      if (!lightcuts::lightContribution(l, g, sp, mg, wi, dist)) continue;
      Color v = vis(wi, dist);
      if (isBlack(v)) continue;
      double c = luminance(mg * v * l.intensity);
      // The clamp is min(1, 1/(q d^2)); without it the attenuation would be 1/(q d^2).
      // Where it does not clamp, the light is the same with or without it: counted as c
      // itself (dividing out the float attenuation and multiplying the exact one back left
      // a rounding of either sign, which summed to "removes -0.0%").
      const double qd2 = double(g.atten.quadratic) * dist * dist;
      double free = g.atten.quadratic > 0 && g.atten(dist) >= 1.0f && qd2 > 0 ? c / qd2 : c;
      clamped[i] += c;
      unclamped[i] += free;
    }
  });
  double a = 0, b = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    a += clamped[i];
    b += unclamped[i];
  }
  return b > 0 ? std::max(0.0, 1 - a / b) : 0;
}

PixelAovs primaryAovs(const Scene& scene, const RenderOptions& o) {
  PixelAovs a;
  const size_t n = size_t(o.width) * size_t(o.height);
  a.albedo.assign(n, Color(0));
  a.normal.assign(n, Vec3(0, 0, 0));
  a.depth.assign(n, kInf);
  std::unique_ptr<tbb::global_control> threads;
  if (o.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
  const scene::Camera& cam = scene.camera();
  tbb::parallel_for(0, o.height, [&](int y) {
    for (int x = 0; x < o.width; ++x) {
      Vec3 d = normalize(cam.direction((float(x) + 0.5f) / float(o.width), (float(y) + 0.5f) / float(o.height)));
      Hit h;
      if (!scene.intersect(Ray{cam.eye, d, 0, kInf}, h)) continue;
      size_t i = size_t(y) * size_t(o.width) + size_t(x);
      a.albedo[i] = scene.shadingMaterial(h).kd;
      a.normal[i] = h.ns;
      a.depth[i] = h.t;
    }
  });
  return a;
}

Color traceRay(const Scene& scene, const LightEvaluator& evaluator, const Ray& ray, int maxDepth,
               EvalStats& stats) {
  Tracer tr{scene, evaluator, maxDepth, stats};
  return tr.trace(ray, 0);
}

namespace {

// The automatic error floor: kAutoErrorFloorFraction of the mean luminance of up to
// kErrorFloorGrid^2 pixel centres spread over the image, rendered without a floor.
float autoErrorFloor(const Scene& scene, const LightEvaluator& evaluator, const RenderOptions& o, uint64_t& pixels) {
  RenderOptions pre = o;
  pre.spp = 1;
  pre.errorFloor = 0;
  const int gx = std::min(o.width, kErrorFloorGrid), gy = std::min(o.height, kErrorFloorGrid);
  pixels = uint64_t(gx) * uint64_t(gy);
  std::vector<double> lum(pixels, 0.0);
  tbb::enumerable_thread_specific<EvalStats> stats;
  tbb::parallel_for(0, gx * gy, [&](int i) {
    if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
    const int x = int((int64_t(i % gx) * 2 + 1) * o.width / (2 * gx)), y = int((int64_t(i / gx) * 2 + 1) * o.height / (2 * gy));
    uint64_t a = 0, b = 0;
    lum[size_t(i)] = std::max(0.0f, luminance(renderPixel(scene, evaluator, pre, x, y, stats.local(), a, b).color));
  });
  double sum = 0;
  for (double l : lum) sum += l;  // in pixel order: the same floor whatever the threads
  double mean = pixels > 0 ? sum / double(pixels) : 0;
  return std::isfinite(mean) ? float(kAutoErrorFloorFraction * mean) : 0.0f;
}

}  // namespace

TileRect TileGrid::rect(int t) const {
  int tx = t % tilesX, ty = t / tilesX;
  return {tx * tile, ty * tile, std::min(width, (tx + 1) * tile), std::min(height, (ty + 1) * tile)};
}

TileGrid tileGrid(const RenderOptions& o, const LightEvaluator& evaluator) {
  const int S = o.reconstructSpacing;
  const bool recon = S > 1 && evaluator.supportsReconstruction();
  const int C = std::max(S, o.reconstructCoarseSpacing);
  TileGrid g;
  g.width = o.width;
  g.height = o.height;
  g.tile = recon ? (64 + C - 1) / C * C : 16;
  g.tilesX = (o.width + g.tile - 1) / g.tile;
  g.tilesY = (o.height + g.tile - 1) / g.tile;
  return g;
}

RenderResult render(const Scene& scene, const LightEvaluator& evaluator, const RenderOptions& given) {
  RenderResult res;
  RenderOptions o = given;
  std::unique_ptr<tbb::global_control> floorThreads;
  if (o.threads > 0)
    floorThreads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
  const auto tFloor = Clock::now();
  if (o.errorFloor < 0) {
    o.errorFloor = evaluator.method() == lightcuts::Method::Lightcuts
                       ? autoErrorFloor(scene, evaluator, o, res.stats.errorFloorPixels)
                       : 0.0f;
  }
  if (!std::isfinite(o.errorFloor)) o.errorFloor = 0;
  res.stats.errorFloor = o.errorFloor;
  const double floorSeconds = secondsSince(tFloor);
  res.image = io::Image(o.width, o.height);
  res.cutSize.assign(size_t(o.width) * size_t(o.height), 0.0f);
  res.done.assign(size_t(o.width) * size_t(o.height), 0);
  res.shadowRays.assign(size_t(o.width) * size_t(o.height), 0.0f);
  res.aaFlagged.assign(size_t(o.width) * size_t(o.height), 0);
  std::unique_ptr<tbb::global_control> threads;
  if (o.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(o.threads));

  struct Local {
    EvalStats stats;
    uint64_t primary = 0, secondary = 0;
    uint64_t samples = 0, fallbacks = 0;
    std::vector<CutSample> slots;   // reconstruction samples of the current tile, per pixel
    std::vector<uint8_t> slotState;
    std::vector<const CutSample*> slotSample;
    uint64_t coarseCells = 0;
    uint64_t tiles = 0, pixels = 0;
    CellCuts cell;                  // merged cuts of the current cell
    uint64_t aaPixels = 0, aaSubs = 0;
    AaCutCache aaCache;             // merged cuts of antialiasing's sub-samples
  };
  tbb::enumerable_thread_specific<Local> locals;
  // Reconstruction cuts: samples at the pixels whose x and y are multiples of S (and the
  // last row and column). Tiles are whole cells wide so a tile needs only the samples on
  // its cells' corners; those on its right and bottom edges are shared with the next
  // tiles (EdgeSamples).
  const int S = o.reconstructSpacing;
  const bool recon = S > 1 && evaluator.supportsReconstruction();
  const int C = std::max(S, o.reconstructCoarseSpacing);
  const TileGrid grid = tileGrid(o, evaluator);
  const int kTile = grid.tile;
  RenderOptions centre = o;  // samples are traced through pixel centres
  centre.spp = 1;
  centre.progress = nullptr;
  EdgeSamples edges(recon ? o.width : 0, recon ? o.height : 0, kTile);
  std::atomic<int> tilesDone{0};
  std::atomic<bool> finished{false};
  int totalTiles = grid.count();
  WorkShare* share = o.share;
  if (share) share->begin(grid, res);

  // Progress is reported from its own thread so rendering threads never wait on output.
  std::mutex mu;
  std::condition_variable cv;
  std::thread reporter;
  auto fraction = [&] { return share ? share->fractionDone() : double(tilesDone) / double(totalTiles); };
  if (o.progress) {
    reporter = std::thread([&] {
      std::unique_lock<std::mutex> lock(mu);
      while (!finished) {
        o.progress(fraction());
        cv.wait_for(lock, std::chrono::milliseconds(100));
      }
    });
  }

  auto t0 = Clock::now();
  std::atomic<int64_t> lastTileNs{0};  // when the last tile rendered here was done
  // One tile; false when cancelled inside it.
  auto renderTile = [&](Local& L, int t) {
    const TileRect tr = grid.rect(t);
    const int x0 = tr.x0, y0 = tr.y0, x1 = tr.x1, y1 = tr.y1;
    if (!recon) {
      // Cancellation is checked at every pixel: one tile of many samples can take seconds.
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return false;
          storePixel(res, o.width, x, y, renderPixel(scene, evaluator, o, x, y, L.stats, L.primary, L.secondary));
        }
      adaptiveTile(scene, evaluator, o, res, L.stats, L.primary, L.secondary, L.aaPixels, L.aaSubs, L.fallbacks, x0, y0,
                   x1, y1, nullptr, nullptr);
    } else {
      ReconstructionTile rt{scene, evaluator, o, centre, L.stats, L.primary, L.secondary, L.samples, L.fallbacks,
                            L.coarseCells, L.slots, L.slotState, L.slotSample, L.cell, res, edges, x0, y0, x1, y1};
      rt.run(S, C);
      adaptiveTile(scene, evaluator, o, res, L.stats, L.primary, L.secondary, L.aaPixels, L.aaSubs, L.fallbacks, x0, y0,
                   x1, y1, &rt, &L.aaCache);
      edges.tileDone(x0, y0, x1, y1);
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return false;
    }
    ++L.tiles;
    L.pixels += uint64_t(x1 - x0) * uint64_t(y1 - y0);
    ++tilesDone;
    int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
    for (int64_t prev = lastTileNs.load(); prev < ns && !lastTileNs.compare_exchange_weak(prev, ns);) {
    }
    return true;
  };
  if (!share) {
    tbb::parallel_for(tbb::blocked_range2d<int>(0, grid.tilesY, 1, 0, grid.tilesX, 1),
                      [&](const tbb::blocked_range2d<int>& r) {
                        Local& L = locals.local();
                        for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
                          for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
                            if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
                            if (!renderTile(L, ty * grid.tilesX + tx)) return;
                          }
                      });
  } else {
    // Each worker asks the share for tiles until none is left.
    const int workers = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    tbb::parallel_for(0, std::max(1, workers), 1, [&](int) {
      Local& L = locals.local();
      for (int t; (t = share->next()) >= 0;) {
        if (!renderTile(L, t)) return;
        share->rendered(t, res);
      }
    });
    share->endTiles();
  }
  res.stats.tileSeconds = double(lastTileNs.load()) * 1e-9;
  res.stats.seconds = secondsSince(t0) + floorSeconds;
  {
    std::lock_guard<std::mutex> lock(mu);
    finished = true;
  }
  cv.notify_all();
  if (reporter.joinable()) reporter.join();
  if (o.progress) o.progress(fraction());
  // A cancelled render may stop inside a tile (tiles check at every pixel).
  res.interrupted = o.cancel && o.cancel->load() && std::find(res.done.begin(), res.done.end(), 0) != res.done.end();

  for (const Local& L : locals) {
    res.stats.eval.add(L.stats);
    res.stats.primaryRays += L.primary;
    res.stats.secondaryRays += L.secondary;
    res.stats.reconstructionSamples += L.samples;
    res.stats.reconstructionFallbacks += L.fallbacks;
    res.stats.reconstructionCoarseCells += L.coarseCells;
    res.stats.tiles += L.tiles;
    res.stats.pixels += L.pixels;
    res.stats.aaPixels += L.aaPixels;
    res.stats.aaSubSamples += L.aaSubs;
  }

  // Brute force at sampled pixels: the measured error, and what a full brute-force image
  // would cost, without rendering one.
  if (o.referencePixels > 0 && !res.interrupted && evaluator.method() != lightcuts::Method::Brute) {
    auto brute = lightcuts::makeBruteForce(scene.lights());
    auto px = referencePixelSet(o.referencePixels, o.width, o.height);
    std::vector<Color> ref(px.size()), test(px.size());
    EvalStats bruteStats, testStats;
    auto tb = Clock::now();
    tbb::enumerable_thread_specific<EvalStats> bs;
    // A distributed render computes its share here (every pixel's colour depends only on
    // the pixel) and gathers the rest.
    auto mine = [&](size_t i) { return !share || share->ownsReference(i); };
    size_t own = 0;
    for (size_t i = 0; i < px.size(); ++i) own += mine(i);
    Progress progress(o.referenceProgress, double(own));
    tbb::parallel_for(size_t(0), px.size(), [&](size_t i) {
      if (!mine(i)) return;
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
      ref[i] = pixelWithSubSamples(scene, *brute, o, res, px[i].first, px[i].second, bs.local());
      progress.add(1);
    });
    progress.finish();
    for (const EvalStats& s : bs) bruteStats.add(s);
    if (share && !(o.cancel && o.cancel->load())) {
      share->gatherReference(ref, bruteStats);
      // Another rank knew which pixels adaptive antialiasing re-sampled only in its own
      // tiles; the gathering process, which has every tile now, redoes the other flagged
      // ones at their sub-samples.
      if (share->gathers()) {
        EvalStats redo;
        for (size_t i = 0; i < px.size(); ++i)
          if (!mine(i) && res.aaFlagged[size_t(px[i].second) * size_t(o.width) + size_t(px[i].first)])
            ref[i] = pixelWithSubSamples(scene, *brute, o, res, px[i].first, px[i].second, redo);
      }
    }
    // Stopped during the reference: the image is whole, but the run is interrupted.
    if (o.cancel && o.cancel->load()) {
      res.interrupted = true;
      return res;
    }
    res.stats.reference.bruteSeconds = secondsSince(tb);
    res.stats.reference.localPixels = int(own);
    if (share && !share->gathers()) return res;  // the gathering process reports the error
    // The error is that of the rendered image; the time, that of the method on these pixels
    // alone (under reconstruction cuts, the render's time per pixel).
    for (size_t i = 0; i < px.size(); ++i)
      test[i] = res.image.pixels[size_t(px[i].second) * size_t(o.width) + size_t(px[i].first)];
    if (recon) {
      res.stats.reference.testSeconds = res.stats.seconds * double(px.size()) / (double(o.width) * double(o.height));
    } else {
      auto tt = Clock::now();
      for (size_t i = 0; i < px.size(); ++i)
        (void)pixelWithSubSamples(scene, evaluator, o, res, px[i].first, px[i].second, testStats);
      res.stats.reference.testSeconds = secondsSince(tt);
    }
    ReferenceStats& rs = res.stats.reference;
    rs.pixels = int(px.size());
    double area = double(o.width) * double(o.height);
    rs.bruteSecondsEstimate = rs.bruteSeconds * area / double(px.size());
    rs.bruteLightsPerShadingPoint =
        bruteStats.shadingPoints ? double(bruteStats.cutNodes) / double(bruteStats.shadingPoints) : 0;
    // Relative error against max(reference luminance, 1% of the mean), as `compare` does.
    double mean = 0;
    for (const Color& c : ref) mean += luminance(c);
    mean /= double(std::max<size_t>(1, ref.size()));
    double floor = std::max(0.01 * mean, 1e-6);
    std::vector<double> rel(px.size());
    for (size_t i = 0; i < px.size(); ++i)
      rel[i] = std::fabs(double(luminance(test[i])) - double(luminance(ref[i]))) /
               std::max(double(luminance(ref[i])), floor);
    std::sort(rel.begin(), rel.end());
    double sum = 0;
    size_t over = 0;
    for (double r : rel) {
      sum += r;
      over += r > ReferenceStats::kThreshold;
    }
    rs.meanRelativeError = sum / double(std::max<size_t>(1, rel.size()));
    rs.maxRelativeError = rel.empty() ? 0 : rel.back();
    rs.p99RelativeError = rel.empty() ? 0 : rel[std::min(rel.size() - 1, size_t(std::ceil(0.99 * double(rel.size()))) - 1)];
    rs.fractionOver2pct = rel.empty() ? 0 : double(over) / double(rel.size());
  }
  return res;
}

}  // namespace lc::render
