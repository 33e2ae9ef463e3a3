#include "render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

#include "core/rng.h"

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

// Shadow rays from one shading point, offset off the surface toward the light and stopped
// just short of it (a light on a surface is never blocked by that surface).
class ShadowRays final : public lightcuts::Visibility {
 public:
  ShadowRays(const Scene& s, const Hit& h) : scene_(s), p_(h.p), ng_(h.ng), eps_(s.epsilon()) {}
  Color operator()(const Vec3& wi, float dist) override {
    Vec3 o = p_ + ng_ * (dot(wi, ng_) >= 0 ? eps_ : -eps_);
    float tmax = std::isinf(dist) ? kInf : dist - 2 * eps_;
    if (!(tmax > 0)) return Color(1);
    return scene_.transmittance(o, wi, tmax);
  }

 private:
  const Scene& scene_;
  Vec3 p_, ng_;
  float eps_;
};

struct Tracer {
  const Scene& scene;
  const LightEvaluator& evaluator;
  int maxDepth;
  EvalStats& stats;
  uint64_t secondaryRays = 0;
  uint64_t cutNodes = 0;  // summed over the shading points of the current sample

  Color trace(const Ray& ray, int depth) {
    Hit h;
    if (!scene.intersect(ray, h)) return Color(0);
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
      ShadowRays vis(scene, h);
      lightcuts::EvalResult r = evaluator.evaluate(sp, vis, stats);
      L += r.radiance;
      cutNodes += r.cutSize;
    }
    if (depth >= maxDepth) return L;
    if (!isBlack(m.kr)) {
      Vec3 r = normalize(reflect(v, h.ns));
      ++secondaryRays;
      L += m.kr * trace(Ray{scene.offsetOrigin(h, r), r, 0, kInf}, depth + 1);
    }
    if (!isBlack(m.kt)) {
      // Entering through the front face goes from air (index 1) into the material.
      float eta = h.frontFace ? 1.0f / m.ior : m.ior;
      float cosI = std::min(1.0f, dot(v, h.ns));
      float sin2T = eta * eta * (1 - cosI * cosI);
      Vec3 t;
      if (sin2T >= 1) {
        t = normalize(reflect(v, h.ns));  // total internal reflection
      } else {
        t = normalize(-v * eta + h.ns * (eta * cosI - std::sqrt(1 - sin2T)));
      }
      ++secondaryRays;
      L += m.kt * trace(Ray{scene.offsetOrigin(h, t), t, 0, kInf}, depth + 1);
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
};

PixelResult renderPixel(const Scene& scene, const LightEvaluator& ev, const RenderOptions& o, int x, int y,
                        EvalStats& stats, uint64_t& primary, uint64_t& secondary) {
  Rng rng(o.seed, uint64_t(y) * uint64_t(o.width) + uint64_t(x));
  Tracer tr{scene, ev, o.maxDepth, stats};
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
  return {sum / float(o.spp), float(tr.cutNodes) / float(o.spp)};
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
      double free = g.atten.quadratic > 0 ? c / g.atten(dist) / (double(g.atten.quadratic) * dist * dist) : c;
      clamped[i] += c;
      unclamped[i] += free;
    }
  });
  double a = 0, b = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    a += clamped[i];
    b += unclamped[i];
  }
  return b > 0 ? 1 - a / b : 0;
}

Color traceRay(const Scene& scene, const LightEvaluator& evaluator, const Ray& ray, int maxDepth,
               EvalStats& stats) {
  Tracer tr{scene, evaluator, maxDepth, stats};
  return tr.trace(ray, 0);
}

RenderResult render(const Scene& scene, const LightEvaluator& evaluator, const RenderOptions& o) {
  RenderResult res;
  res.image = io::Image(o.width, o.height);
  res.cutSize.assign(size_t(o.width) * size_t(o.height), 0.0f);
  res.done.assign(size_t(o.width) * size_t(o.height), 0);
  std::unique_ptr<tbb::global_control> threads;
  if (o.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(o.threads));

  struct Local {
    EvalStats stats;
    uint64_t primary = 0, secondary = 0;
  };
  tbb::enumerable_thread_specific<Local> locals;
  constexpr int kTile = 16;
  int tilesX = (o.width + kTile - 1) / kTile, tilesY = (o.height + kTile - 1) / kTile;
  std::atomic<int> tilesDone{0};
  std::atomic<bool> finished{false};
  int totalTiles = tilesX * tilesY;

  // Progress is reported from its own thread so rendering threads never wait on output.
  std::mutex mu;
  std::condition_variable cv;
  std::thread reporter;
  if (o.progress) {
    reporter = std::thread([&] {
      std::unique_lock<std::mutex> lock(mu);
      while (!finished) {
        o.progress(double(tilesDone) / double(totalTiles));
        cv.wait_for(lock, std::chrono::milliseconds(100));
      }
    });
  }

  auto t0 = Clock::now();
  tbb::parallel_for(tbb::blocked_range2d<int>(0, tilesY, 1, 0, tilesX, 1), [&](const tbb::blocked_range2d<int>& r) {
    Local& L = locals.local();
    for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
      for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
        if (o.cancel && o.cancel->load(std::memory_order_relaxed)) return;
        int x1 = std::min(o.width, (tx + 1) * kTile), y1 = std::min(o.height, (ty + 1) * kTile);
        for (int y = ty * kTile; y < y1; ++y)
          for (int x = tx * kTile; x < x1; ++x) {
            PixelResult p = renderPixel(scene, evaluator, o, x, y, L.stats, L.primary, L.secondary);
            size_t i = size_t(y) * size_t(o.width) + size_t(x);
            res.image.pixels[i] = p.color;
            res.cutSize[i] = p.cut;
            res.done[i] = 1;
          }
        ++tilesDone;
      }
  });
  res.stats.seconds = secondsSince(t0);
  {
    std::lock_guard<std::mutex> lock(mu);
    finished = true;
  }
  cv.notify_all();
  if (reporter.joinable()) reporter.join();
  if (o.progress) o.progress(double(tilesDone) / double(totalTiles));
  res.interrupted = o.cancel && o.cancel->load() && tilesDone < totalTiles;

  for (const Local& L : locals) {
    res.stats.eval.add(L.stats);
    res.stats.primaryRays += L.primary;
    res.stats.secondaryRays += L.secondary;
  }

  // Brute force at sampled pixels: the measured error, and what a full brute-force image
  // would cost, without rendering one.
  if (o.referencePixels > 0 && !res.interrupted && evaluator.method() != lightcuts::Method::Brute) {
    auto brute = lightcuts::makeBruteForce(scene.lights());
    auto px = referencePixelSet(o.referencePixels, o.width, o.height);
    std::vector<Color> ref(px.size()), test(px.size());
    EvalStats bruteStats, testStats;
    uint64_t dummyA = 0, dummyB = 0;
    auto tb = Clock::now();
    tbb::enumerable_thread_specific<EvalStats> bs;
    tbb::parallel_for(size_t(0), px.size(), [&](size_t i) {
      uint64_t a = 0, b = 0;
      ref[i] = renderPixel(scene, *brute, o, px[i].first, px[i].second, bs.local(), a, b).color;
    });
    res.stats.reference.bruteSeconds = secondsSince(tb);
    for (const EvalStats& s : bs) bruteStats.add(s);
    auto tt = Clock::now();
    for (size_t i = 0; i < px.size(); ++i)
      test[i] = renderPixel(scene, evaluator, o, px[i].first, px[i].second, testStats, dummyA, dummyB).color;
    res.stats.reference.testSeconds = secondsSince(tt);
    (void)testStats;
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
      over += r > 0.02;
    }
    rs.meanRelativeError = sum / double(std::max<size_t>(1, rel.size()));
    rs.maxRelativeError = rel.empty() ? 0 : rel.back();
    rs.p99RelativeError = rel.empty() ? 0 : rel[std::min(rel.size() - 1, size_t(std::ceil(0.99 * double(rel.size()))) - 1)];
    rs.fractionOver2pct = rel.empty() ? 0 : double(over) / double(rel.size());
  }
  return res;
}

}  // namespace lc::render
