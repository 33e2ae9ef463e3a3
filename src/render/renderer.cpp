// The tile loop: the image in tiles rendered in parallel (or handed out by a WorkShare),
// each pixel traced by the tracer (tracer.h), under reconstruction cuts by cells of
// samples (reconstruction_tiles.h), then antialiased (adaptive.h); the automatic error
// floor's pre-pass before, the reference pixels (reference_pixels.h) after.
#include "render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include "render/adaptive.h"
#include "render/reconstruction_tiles.h"
#include "render/reference_pixels.h"
#include "render/tracer.h"

namespace lc::render {

namespace {

using lightcuts::EvalStats;
using lightcuts::LightEvaluator;
using scene::Hit;
using scene::Ray;
using scene::Scene;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

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

namespace {

// The automatic error floor: kAutoErrorFloorFraction of the mean luminance of up to
// kErrorFloorGrid^2 pixel centres spread over the image, rendered without a floor.
float autoErrorFloor(const Scene& scene, const LightEvaluator& evaluator, const RenderOptions& o, uint64_t& pixels,
                     EvalStats& prePass) {
  RenderOptions pre = o;
  pre.spp = 1;
  pre.errorFloor = 0;
  pre.minError = kErrorFloorPrePassError;
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
  stats.combine_each([&](const EvalStats& s) { prePass.add(s); });  // counts: any order
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

// Tiles of reconstruction cuts are about this many pixels wide (whole cells): a tile
// shares the samples on its border with its neighbours, and its sub-samples borrow only
// within it, so larger tiles recompute fewer samples.
constexpr int kReconstructionTile = 64;
// Tiles an image under reconstruction cuts is cut into at least, where its cells allow:
// enough to keep every thread of a small machine busy to the end.
constexpr int64_t kMinTiles = 16;

namespace {
// Whether the render takes reconstruction cuts: a spacing of 1 or more, and an evaluator
// that records cuts (lightcuts).
bool reconstructs(const RenderOptions& o, const LightEvaluator& evaluator) {
  return o.reconstructSpacing >= 1 && evaluator.supportsReconstruction();
}
}  // namespace

TileGrid tileGrid(const RenderOptions& o, const LightEvaluator& evaluator) {
  const int S = o.reconstructSpacing;
  const bool recon = reconstructs(o, evaluator);
  const int C = std::max(S, o.reconstructCoarseSpacing);
  TileGrid g;
  g.width = o.width;
  g.height = o.height;
  g.tile = recon ? (kReconstructionTile + C - 1) / C * C : 16;
  // A small image under reconstruction cuts would be a tile or four, rendered by one or
  // two threads: its tiles shrink (whole cells still) until there are kMinTiles of them.
  // From the image's size alone, so the grid is the same whatever the thread count.
  auto count = [&](int t) { return int64_t((o.width + t - 1) / t) * int64_t((o.height + t - 1) / t); };
  while (recon && count(g.tile) < kMinTiles && g.tile / 2 >= C && g.tile / 2 % C == 0) g.tile /= 2;
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
                       ? autoErrorFloor(scene, evaluator, o, res.stats.errorFloorPixels, res.stats.prePass)
                       : 0.0f;
    // Clear tests stay on only where the pre-pass found them worth their cost.
    o.clearTests = lightcuts::clearTestsPay(res.stats.prePass.clearTests, res.stats.prePass.clearedClusters);
  }
  res.stats.clearTests = o.clearTests;
  if (!std::isfinite(o.errorFloor)) o.errorFloor = 0;
  res.stats.errorFloor = o.errorFloor;
  const double floorSeconds = secondsSince(tFloor);
  res.image = io::Image(o.width, o.height);
  res.cutSize.assign(size_t(o.width) * size_t(o.height), 0.0f);
  res.done.assign(size_t(o.width) * size_t(o.height), 0);
  res.shadowRays.assign(size_t(o.width) * size_t(o.height), 0.0f);
  res.aaFlagged.assign(size_t(o.width) * size_t(o.height), 0);
  res.centreLuminance.assign(size_t(o.width) * size_t(o.height), 0.0f);
  std::unique_ptr<tbb::global_control> threads;
  if (o.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(o.threads));

  // A thread's counters and buffers, reused from tile to tile.
  struct Local {
    TileCounters counts;
    ReconstructionScratch scratch;  // reconstruction samples and merged cuts of the current tile
    AaCutCache aaCache;             // merged cuts of antialiasing's sub-samples
  };
  tbb::enumerable_thread_specific<Local> locals;
  // Reconstruction cuts: samples at the pixels whose x and y are multiples of S (and the
  // last row and column). Tiles are whole cells wide so a tile needs only the samples on
  // its cells' corners; those on its right and bottom edges are shared with the next
  // tiles (EdgeSamples).
  const bool recon = reconstructs(o, evaluator);
  const TileGrid grid = tileGrid(o, evaluator);
  std::optional<ReconstructionRender> reconstruction;
  if (recon) reconstruction.emplace(scene, evaluator, o, grid.tile);
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
    TileCounters& n = L.counts;
    if (!recon) {
      // Cancellation is checked at every pixel: one tile of many samples can take seconds.
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return false;
          storePixel(res, o.width, x, y, renderPixel(scene, evaluator, o, x, y, n.stats, n.primary, n.secondary));
        }
      adaptiveTile(scene, evaluator, o, res, n, tr, nullptr, nullptr);
    } else {
      ReconstructionTile rt(*reconstruction, tr, L.scratch, n, res);
      rt.run();
      adaptiveTile(scene, evaluator, o, res, n, tr, &rt, &L.aaCache);
      reconstruction->edges.tileDone(x0, y0, x1, y1);
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return false;
    }
    ++n.tiles;
    n.pixels += uint64_t(x1 - x0) * uint64_t(y1 - y0);
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
  // The tile borders' luminance, compared across them: on the gathering process, which has
  // every tile now (the others' share of the image is partial).
  if (!(o.cancel && o.cancel->load()) && (!share || share->gathers())) {
    const std::vector<std::pair<int, int>> seams = seamPixels(res, o, grid.tile);
    res.stats.aaSeamPixels = seams.size();
    const int g = aaGridSide(o.aaSamples);
    tbb::parallel_for(size_t(0), seams.size(), [&](size_t k) {
      if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
      resamplePixel(scene, evaluator, o, res, locals.local().counts, seams[k].first, seams[k].second, g, nullptr,
                    nullptr);
    });
    int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
    if (!seams.empty()) lastTileNs = std::max(lastTileNs.load(), ns);
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
    const TileCounters& n = L.counts;
    res.stats.eval.add(n.stats);
    res.stats.primaryRays += n.primary;
    res.stats.secondaryRays += n.secondary;
    res.stats.reconstructionSamples += n.samples;
    res.stats.reconstructionFallbacks += n.fallbacks;
    res.stats.reconstructionCoarseCells += n.coarseCells;
    res.stats.reconstructionSplitCells += n.splitCells;
    res.stats.reconstructionRefinedCells += n.refinedCells;
    res.stats.tiles += n.tiles;
    res.stats.pixels += n.pixels;
    res.stats.aaPixels += n.aaPixels;
    res.stats.aaSubSamples += n.aaSubSamples;
  }

  if (o.referencePixels > 0 && !res.interrupted && evaluator.method() != lightcuts::Method::Brute)
    measureReference(scene, evaluator, o, recon, res);
  return res;
}

}  // namespace lc::render
