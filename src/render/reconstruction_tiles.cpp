#include "render/reconstruction_tiles.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <iterator>

namespace lc::render {

using lightcuts::EvalResult;
using lightcuts::EvalStats;
using lightcuts::ShadingPoint;
using scene::Hit;
using scene::Ray;

bool sameSurface(int shapeA, const Vec3& pa, const Vec3& na, int shapeB, const Vec3& pb, const Vec3& nb) {
  if (shapeA != shapeB || dot(na, nb) < kSampleMinCos) return false;
  Vec3 d = pb - pa;
  return std::fabs(dot(na, d)) <= kSampleMaxPlaneSlope * length(d) &&
         std::fabs(dot(nb, d)) <= kSampleMaxPlaneSlope * length(d);
}

void CellCuts::reset() {
  std::fill(std::begin(ready), std::end(ready), false);
  aaCount = -1;
}

void AaCutCache::reset() {
  for (CellCuts& e : entries) e.reset();
  next = 0;
  pixelSamples.recorded = 0;
}

void AaCutCache::forget(const CutSample* s) {
  for (CellCuts& e : entries)
    if (e.aaCount > 0 && std::find(e.aaSamples, e.aaSamples + e.aaCount, s) != e.aaSamples + e.aaCount) e.reset();
}

CutSample* AaCutCache::newPixelSample(int px, int py) {
  PixelSamples& own = pixelSamples;
  const int i = own.recorded++ % PixelSamples::kMax;
  CutSample* s = &own.slot[i];
  forget(s);
  s->cut.clear();
  own.px[i] = px;
  own.py[i] = py;
  return s;
}

CellCuts* AaCutCache::find(const CutSample* const* set, int k) {
  for (CellCuts& e : entries)
    if (e.aaCount == k && std::equal(set, set + k, e.aaSamples)) return &e;
  CellCuts& e = entries[next];
  next = (next + 1) % kEntries;
  e.reset();
  e.aaCount = k;
  std::copy(set, set + k, e.aaSamples);
  return &e;
}

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

namespace {

// The samples a hit on `shape` with normal n may borrow from: only those on its surface
// and within the footprint limit.
unsigned matchingSamples(const PrimaryHook& h, int shape, const Vec3& p, const Vec3& n) {
  unsigned mask = 0;
  float far2 = length2(p - h.eye) * h.maxSeparation * h.maxSeparation;
  for (int i = 0; i < h.count; ++i) {
    const CutSample& s = *h.samples[i];
    if (s.cut.valid && sameSurface(shape, p, n, s.shape, s.p, s.n) && length2(s.p - p) <= far2) mask |= 1u << i;
  }
  return mask;
}

}  // namespace

unsigned servingSamples(const PrimaryHook& h, int shape, const Vec3& p, const Vec3& n) {
  unsigned mask = matchingSamples(h, shape, p, n);
  return mask != 0 && (h.preselected || insideSamples(h, mask)) ? mask : 0;
}

EvalResult PrimaryHook::light(const Hit& h, const ShadingPoint& sp, lightcuts::Visibility& vis, EvalStats& stats) {
  // A full cut recorded as sample s.
  auto recordInto = [&](CutSample* s) {
    s->shape = h.shape;
    s->p = h.p;
    s->n = h.ns;
    return cuts->record(sp, vis, stats, s->cut);
  };
  if (record) {
    fallbacks += recordFallback;
    return recordInto(record);
  }
  const lightcuts::CutRecord* sampleCuts[4];
  int k = 0;
  unsigned mask = servingSamples(*this, h.shape, h.p, h.ns);
  for (int i = 0; i < count; ++i)
    if (mask >> i & 1) sampleCuts[k++] = &samples[i]->cut;
  if (k == 0) {
    ++fallbacks;
    return cuts->full(sp, vis, stats);
  }
  if (!cell->ready[mask]) {
    cuts->merge(sampleCuts, k, cell->merged[mask]);
    cell->ready[mask] = true;
  }
  const uint64_t refuting = stats.refutingGroupProbes;
  const EvalStats::PointCounts points = stats.pointCounts();
  EvalResult r = cuts->rebuild(sp, vis, stats, cell->merged[mask]);
  if (!(refine && stats.refutingGroupProbes != refuting)) return r;
  // A sub-sample whose probe refutes its samples: a full cut, which the sub-samples after
  // it may borrow (a cell's pixels are refined by ReconstructionTile::cellPixels instead).
  stats.restorePointCounts(points);
  ++fallbacks;
  return aaCache ? recordInto(aaCache->newPixelSample(px, py)) : cuts->full(sp, vis, stats);
}

EdgeSamples::EdgeSamples(int width, int height, int tile)
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

EdgeSamples::Entry* EdgeSamples::at(int x, int y) {
  if (onLineX(x)) return &entries_[size_t(x / tile_ - 1) * size_t(height_) + size_t(y)];
  if (onLineY(y))
    return &entries_[size_t(linesX_) * size_t(height_) + size_t(y / tile_ - 1) * size_t(width_) + size_t(x)];
  return nullptr;
}

void EdgeSamples::tileDone(int x0, int y0, int x1, int y1) {
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

namespace {
RenderOptions centreOptions(const RenderOptions& o) {
  RenderOptions c = o;  // samples are traced through pixel centres
  c.spp = 1;
  c.progress = nullptr;
  return c;
}
}  // namespace

ReconstructionRender::ReconstructionRender(const scene::Scene& s, const lightcuts::LightEvaluator& e,
                                           const RenderOptions& options, int tile)
    : scene(s), ev(e), cuts(e, s.lights()), o(options), centre(centreOptions(options)),
      spacing(options.reconstructSpacing), coarse(std::max(options.reconstructSpacing, options.reconstructCoarseSpacing)),
      edges(options.width, options.height, tile) {}

ReconstructionTile::ReconstructionTile(ReconstructionRender& render, const TileRect& rect,
                                       ReconstructionScratch& scratch, TileCounters& counters, RenderResult& res)
    : r_(render), o_(render.o), scratch_(scratch), n_(counters), res_(res), x0_(rect.x0), y0_(rect.y0),
      x1_(rect.x1), y1_(rect.y1) {
  const scene::Camera& cam = r_.scene.camera();
  Vec3 a = normalize(cam.direction(0.5f, 0.5f)), b = normalize(cam.direction(0.5f + 1.0f / float(o_.width), 0.5f));
  pixelAngle_ = length(a - b);
  maxSeparation_ = kSampleMaxFootprints * float(r_.spacing) * pixelAngle_;
}

const CutSample& ReconstructionTile::sample(int x, int y) {
  size_t i = slot(x, y);
  CutSample& cs = scratch_.slots[i];
  if (scratch_.shared[i]) return *scratch_.shared[i];
  // On a line between tiles: read the sample if the tile on the other side made it,
  // else make it there for both.
  EdgeSamples::Entry* e = r_.edges.at(x, y);
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
    hook.cuts = &r_.cuts;
    hook.record = &target;
    p = renderPixel(r_.scene, r_.ev, r_.centre, x, y, n_.stats, n_.primary, n_.secondary, &hook);
    ++n_.samples;
    if (publish) {
      e->pixel = p;
      e->state.store(EdgeSamples::kReady, std::memory_order_release);
    }
  }
  scratch_.shared[i] = &target;
  // With one sample per pixel the sample is the pixel; otherwise the pixel is rendered
  // from its samples like any other.
  if (o_.spp == 1 && x < x1_ && y < y1_) {
    storePixel(res_, o_.width, x, y, p);
    scratch_.state[i] |= kDone;
  }
  return target;
}

void ReconstructionTile::run() {
  const int C = r_.coarse;
  size_t n = size_t(x1_ - x0_ + 1) * size_t(y1_ - y0_ + 1);
  if (scratch_.slots.size() < n) scratch_.slots.resize(n);
  scratch_.state.assign(n, 0);
  scratch_.shared.assign(n, nullptr);
  for (int cy = y0_; cy < y1_; cy += C)
    for (int cx = x0_; cx < x1_; cx += C) cellPixels(cx, cy, std::min(C, x1_ - cx), std::min(C, y1_ - cy));
}

// How much of their light a cell's four corners disagree about (disagreementShare), or
// nothing when they do not lie on one surface; their merged cut is made here and kept for
// the cell's pixels.
std::optional<float> ReconstructionTile::cornersDisagreement(const CutSample* const* corners, int n) {
  if (n != 4) return std::nullopt;
  for (int i = 0; i < 4; ++i) {
    if (!corners[i]->cut.valid) return std::nullopt;
    for (int j = i + 1; j < 4; ++j)
      if (!sameSurface(corners[i]->shape, corners[i]->p, corners[i]->n, corners[j]->shape, corners[j]->p,
                       corners[j]->n))
        return std::nullopt;
  }
  const lightcuts::CutRecord* cuts[4];
  for (int i = 0; i < 4; ++i) cuts[i] = &corners[i]->cut;
  lightcuts::MergedCut& merged = scratch_.cell.merged[15];
  r_.cuts.merge(cuts, 4, merged);
  scratch_.cell.ready[15] = true;
  return r_.cuts.disagreement(merged, corners[0]->p, corners[0]->n);
}

// The surface a pixel centre's ray shades (false: none).
bool ReconstructionTile::probe(int x, int y, int& shape, Vec3& p, Vec3& n) const {
  const scene::Camera& cam = r_.scene.camera();
  Ray ray{cam.eye, normalize(cam.direction((float(x) + 0.5f) / float(o_.width), (float(y) + 0.5f) / float(o_.height))),
          0, kInf};
  Hit h;
  if (!r_.scene.intersect(ray, h)) return false;
  scene::ShadingMaterial m = r_.scene.shadingMaterial(h);
  if (isBlack(m.kd) && isBlack(m.ks)) return false;
  shape = h.shape;
  p = h.p;
  n = h.ns;
  return true;
}

// The pixels [cx, cx + w) x [cy, cy + h) still pending; corners at cx + w and cy + h
// (clipped to the image: a last cell's far corner is its own last pixel).
void ReconstructionTile::cellPixels(int cx, int cy, int w, int h) {
  if (o_.cancel && o_.cancel->load(std::memory_order_relaxed)) return;
  bool any = false;
  for (int y = cy; y < cy + h && !any; ++y)
    for (int x = cx; x < cx + w && !any; ++x) any = !(scratch_.state[slot(x, y)] & kDone);
  if (!any) return;
  const int xa = cx, xb = std::min(cx + w, o_.width - 1), ya = cy, yb = std::min(cy + h, o_.height - 1);
  const CutSample* corners[4];
  PrimaryHook hook;
  hook.cuts = &r_.cuts;
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
  CellCuts& cell = scratch_.cell;
  cell.reset();
  hook.samples = corners;
  hook.count = n;
  hook.cell = &cell;
  hook.eye = r_.scene.camera().eye;
  const int spacing = r_.spacing;
  const bool coarse = w > spacing || h > spacing;
  // The footprint limit grows with the cell (a coarse cell's points lie farther from
  // its corners), so on a surface seen face on the cell stays whole.
  hook.maxSeparation = coarse ? maxSeparation_ * float(std::max(w, h)) / float(spacing) : maxSeparation_;
  // At once: its pixels wait for finer cells. A coarse cell splits unless its corners
  // agree; a smaller one (of four corners) when they lie on one surface and disagree about
  // much of their light (RenderOptions::reconstructSplit).
  bool split = false;
  if (coarse) {
    const std::optional<float> d = cornersDisagreement(corners, n);
    split = !d || *d > kCoarseMaxDisagreement;
  } else if (o_.reconstructSplit < 1 && (w > 1 || h > 1)) {
    const std::optional<float> d = cornersDisagreement(corners, n);
    split = d && *d > o_.reconstructSplit;
    n_.splitCells += split;
  }
  bool left = split;  // pixels this cell's samples cannot serve
  n_.coarseCells += coarse && !split;
  // A probe that refutes the corners (RenderOptions::reconstructRefine) stops the cell: its
  // pixels wait for smaller cells, with samples nearer them, those it rebuilt included.
  const bool refine = o_.reconstructRefine && (w > 1 || h > 1);
  const uint64_t refuting = n_.stats.refutingGroupProbes;
  const EvalStats::PointCounts points = n_.stats.pointCounts();
  auto refuted = [&] { return refine && n_.stats.refutingGroupProbes != refuting; };
  scratch_.rebuilt.clear();
  for (int y = cy; y < cy + h && !split && !refuted(); ++y)
    for (int x = cx; x < cx + w && !refuted(); ++x) {
      uint8_t& st = scratch_.state[slot(x, y)];
      if (st & kDone) continue;
      if (o_.cancel && o_.cancel->load(std::memory_order_relaxed)) return;
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
      storePixel(res_, o_.width, x, y,
                 renderPixel(r_.scene, r_.ev, o_, x, y, n_.stats, n_.primary, n_.secondary, &hook));
      n_.fallbacks += hook.fallbacks;
      st |= kDone;
      if (refine) scratch_.rebuilt.push_back(uint32_t(slot(x, y)));
    }
  if (refuted()) {
    n_.stats.restorePointCounts(points);
    for (uint32_t s : scratch_.rebuilt) scratch_.state[s] &= uint8_t(~kDone);
    ++n_.refinedCells;
    left = true;
  }
  if (!left) return;
  int w0 = w > 1 ? w / 2 : w, h0 = h > 1 ? h / 2 : h;
  cellPixels(cx, cy, w0, h0);
  if (w > w0) cellPixels(cx + w0, cy, w - w0, h0);
  if (h > h0) cellPixels(cx, cy + h0, w0, h - h0);
  if (w > w0 && h > h0) cellPixels(cx + w0, cy + h0, w - w0, h - h0);
}

// Whether a surface lies near a sub-sample that borrows from samples it lies beyond
// (kExtrapolationReach in reconstruction_tiles.h): the world distance from the hit to the
// nearest segment between two samples (or to the sample, for one), and, when that is over
// kExtrapolationMinFootprints of the hit's pixel `footprint`, short occlusion rays from it.
bool ReconstructionTile::surfaceNear(const Hit& hit, float footprint, const CutSample* const* chosen, int k,
                                     PrimaryHook& hook) const {
  float d2 = kInf;
  for (int i = 0; i < k; ++i)
    for (int j = i; j < k; ++j) {
      const Vec3 a = chosen[i]->p, e = chosen[j]->p - a;
      const float ee = dot(e, e);
      const float t = ee > 0 ? std::clamp(dot(hit.p - a, e) / ee, 0.0f, 1.0f) : 0.0f;
      d2 = std::min(d2, length2(hit.p - (a + e * t)));
    }
  const float d = std::sqrt(d2);
  if (!(d > kExtrapolationMinFootprints * footprint)) return false;
  const Vec3 o = hit.p + hit.ns * (kSeparationLift * r_.scene.epsilon());
  Vec3 u, v;
  orthonormalBasis(hit.ns, u, v);
  const Vec3 dirs[kExtrapolationRays] = {hit.ns, normalize(hit.ns + u), normalize(hit.ns - u), normalize(hit.ns + v),
                                         normalize(hit.ns - v)};
  static_assert(kExtrapolationRays == 5);
  const float reach = kExtrapolationReach * d;
  for (const Vec3& dir : dirs) {
    ++hook.separationRays;
    if (r_.scene.occluded(o, dir, reach)) return true;
  }
  return false;
}

void ReconstructionTile::subSampleHook(const Ray& ray, int x, int y, Vec2 u, PrimaryHook& hook,
                                       const CutSample** chosen, AaCutCache& cache) const {
  const scene::Camera& cam = r_.scene.camera();
  hook.cuts = &r_.cuts;
  hook.samples = chosen;
  hook.eye = cam.eye;
  hook.maxSeparation = maxSeparation_;
  // Hull tests at the sub-sample's own position, in 1/kSub pixel units (sample pixels
  // at their centres).
  constexpr int kSub = 16;
  hook.px = x * kSub + std::min(kSub - 1, int(u.x * float(kSub)));
  hook.py = y * kSub + std::min(kSub - 1, int(u.y * float(kSub)));
  hook.preselected = true;
  hook.refine = o_.reconstructRefine;
  if (o_.aaPixelSamples) hook.aaCache = &cache;
  Hit hit;
  if (r_.scene.intersect(ray, hit)) {
    const float far2 = length2(hit.p - cam.eye) * maxSeparation_ * maxSeparation_;
    const int R = 2 * std::max(1, r_.spacing);
    // Per quadrant: the nearest sample's squared distance, position (sub-pixel units) and
    // pixel distance (Chebyshev; 0 for the pixel's own samples).
    int bd[4] = {INT32_MAX, INT32_MAX, INT32_MAX, INT32_MAX}, bx[4] = {}, by[4] = {}, bp[4] = {};
    const CutSample* best[4] = {};
    auto consider = [&](const CutSample* cs, int sx, int sy, int pixels, float reach2) {
      if (!cs || !cs->cut.valid || !sameSurface(hit.shape, hit.p, hit.ns, cs->shape, cs->p, cs->n) ||
          length2(cs->p - hit.p) > reach2)
        return;
      // Quadrants and distances around the sub-sample's own position.
      const int dx = sx - hook.px, dy = sy - hook.py, d = dx * dx + dy * dy;
      for (int q = 0; q < 4; ++q)
        if (((q & 1) ? dx >= 0 : dx <= 0) && ((q & 2) ? dy >= 0 : dy <= 0) && d < bd[q]) {
          bd[q] = d;
          best[q] = cs;
          bx[q] = sx;
          by[q] = sy;
          bp[q] = pixels;
        }
    };
    for (int Y = std::max(y0_, y - R); Y <= std::min({y1_, y + R, o_.height - 1}); ++Y)
      for (int X = std::max(x0_, x - R); X <= std::min({x1_, x + R, o_.width - 1}); ++X)
        consider(scratch_.shared[slot(X, Y)], X * kSub + kSub / 2, Y * kSub + kSub / 2,
                 std::max(std::abs(X - x), std::abs(Y - y)), far2);
    const float footprint = pixelAngle_ * length(hit.p - cam.eye);
    PixelSamples& own = cache.pixelSamples;
    const float ownReach = kPixelSampleMaxFootprints * footprint;
    for (int i = 0; i < own.count(); ++i) {
      const int pixels = std::max(std::abs(own.px[i] / kSub - x), std::abs(own.py[i] / kSub - y));
      if (pixels <= 1) consider(&own.slot[i], own.px[i], own.py[i], pixels, ownReach * ownReach);
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
      hook.cx[k] = bx[q];
      hook.cy[k] = by[q];
      nearest = std::min(nearest, bp[q]);
      ++k;
    }
    hook.count = k;
    if (k > 0 && !insideSamples(hook, (1u << k) - 1)) {
      if (nearest > 1 || (o_.aaExtrapolationProbe && surfaceNear(hit, footprint, chosen, k, hook))) hook.count = 0;
    }
    // A sample on the sub-sample's surface but cut off from it by another surface (the
    // segment between them, lifted off the surface, is blocked: a screen's crossbar across
    // the face of its upright, a box standing on a floor) may see lights the sub-sample
    // does not, on nodes the other samples agree about: then no sample serves it, and it
    // takes a full cut. (Borrowing from the other samples alone did worse: the cut-off
    // sample's disagreements are what send the rebuilt cut's rays. On a pierced screen,
    // scripts/gen_screen_hall.py, 0.98% -> 0.68% of pixels over 2% for +8% rays;
    // docs/LIGHTCUTS.md, "Sub-samples cut off from their samples".) Each distinct sample
    // is tested once, and only when the samples would serve it otherwise.
    if (o_.aaSeparationTest) {
      const float lift = kSeparationLift * r_.scene.epsilon();
      const Vec3 a = hit.p + hit.ns * lift;
      for (int i = 0; i < hook.count; ++i) {
        const Vec3 d = chosen[i]->p + chosen[i]->n * lift - a;
        const float len = length(d);
        if (!(len > 0)) continue;
        ++hook.separationRays;
        if (r_.scene.occluded(a, d / len, len)) hook.count = 0;
      }
    }
    // A full cut: recorded as a pixel sample (over the oldest, once all kMax are taken).
    if (hook.count == 0 && o_.aaPixelSamples) {
      hook.record = cache.newPixelSample(hook.px, hook.py);
      hook.recordFallback = true;
    }
  }
  hook.cell = cache.find(chosen, hook.count);
}

}  // namespace lc::render
