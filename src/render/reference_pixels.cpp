#include "render/reference_pixels.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "core/progress.h"
#include "core/rng.h"
#include "io/image_metrics.h"
#include "render/adaptive.h"
#include "render/tracer.h"

namespace lc::render {

namespace {
using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

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

void measureReference(const scene::Scene& scene, const lightcuts::LightEvaluator& evaluator, const RenderOptions& o,
                      bool reconstructed, RenderResult& res) {
  WorkShare* share = o.share;
  auto brute = lightcuts::makeBruteForce(scene.lights());
  auto px = referencePixelSet(o.referencePixels, o.width, o.height);
  std::vector<Color> ref(px.size()), test(px.size());
  lightcuts::EvalStats bruteStats, testStats;
  auto tb = Clock::now();
  tbb::enumerable_thread_specific<lightcuts::EvalStats> bs;
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
  for (const lightcuts::EvalStats& s : bs) bruteStats.add(s);
  if (share && !(o.cancel && o.cancel->load())) {
    share->gatherReference(ref, bruteStats);
    // Another rank knew which pixels adaptive antialiasing re-sampled only in its own
    // tiles; the gathering process, which has every tile now, redoes the other flagged
    // ones at their sub-samples.
    if (share->gathers()) {
      lightcuts::EvalStats redo;
      for (size_t i = 0; i < px.size(); ++i)
        if (!mine(i) && res.aaFlagged[size_t(px[i].second) * size_t(o.width) + size_t(px[i].first)])
          ref[i] = pixelWithSubSamples(scene, *brute, o, res, px[i].first, px[i].second, redo);
    }
  }
  // Stopped during the reference: the image is whole, but the run is interrupted.
  if (o.cancel && o.cancel->load()) {
    res.interrupted = true;
    return;
  }
  res.stats.reference.bruteSeconds = secondsSince(tb);
  res.stats.reference.localPixels = int(own);
  if (share && !share->gathers()) return;  // the gathering process reports the error
  // The error is that of the rendered image; the time, that of the method on these pixels
  // alone (under reconstruction cuts, the render's time per pixel).
  for (size_t i = 0; i < px.size(); ++i)
    test[i] = res.image.pixels[size_t(px[i].second) * size_t(o.width) + size_t(px[i].first)];
  if (reconstructed) {
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
  // Relative error against max(reference luminance, 1% of the mean), as `compare` does
  // (io/image_metrics.h: relativeError, p99Rank, kMinRelativeFloor). Not compareImages
  // itself, which would change the reported numbers in their last digits: here luminance
  // is lc::luminance's float (compare's is in double), the floor is 0.01 x the mean (not
  // 0.01 x the sum, over n) and the mean error is summed in ascending order.
  double mean = 0;
  for (const Color& c : ref) mean += luminance(c);
  mean /= double(std::max<size_t>(1, ref.size()));
  double floor = std::max(0.01 * mean, io::kMinRelativeFloor);
  std::vector<double> rel(px.size());
  for (size_t i = 0; i < px.size(); ++i)
    rel[i] = io::relativeError(double(luminance(ref[i])), double(luminance(test[i])), floor);
  std::vector<size_t> order(px.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  const size_t shown = std::min(order.size(), ReferenceStats::kWorstPixels);
  // Worst first; ties in pixel order, so the list is the same at any thread count.
  std::partial_sort(order.begin(), order.begin() + ptrdiff_t(shown), order.end(),
                    [&](size_t a, size_t b) { return rel[a] > rel[b] || (rel[a] == rel[b] && a < b); });
  res.stats.reference.worst.clear();
  for (size_t k = 0; k < shown; ++k) {
    const size_t i = order[k];
    res.stats.reference.worst.push_back({px[i].first, px[i].second, luminance(ref[i]), luminance(test[i]), rel[i]});
  }
  std::sort(rel.begin(), rel.end());
  double sum = 0;
  size_t over = 0;
  for (double r : rel) {
    sum += r;
    over += r > ReferenceStats::kThreshold;
  }
  rs.meanRelativeError = sum / double(std::max<size_t>(1, rel.size()));
  rs.maxRelativeError = rel.empty() ? 0 : rel.back();
  rs.p99RelativeError = rel.empty() ? 0 : rel[io::p99Rank(rel.size()) - 1];
  rs.fractionOver2pct = rel.empty() ? 0 : double(over) / double(rel.size());
}

double vplClampedFraction(const scene::Scene& scene, const RenderOptions& o, int points, uint64_t maxEvaluations) {
  const LightSet& ls = scene.lights();
  // The VPLs' indices in order, listed by blocks in parallel (grown push by push on one
  // thread, 8.1M of them took 0.16 s after a 10M-path render).
  constexpr size_t kBlock = size_t(1) << 18;
  const size_t blocks = (ls.lights.size() + kBlock - 1) / kBlock;
  auto isVpl = [&](size_t i) { return ls.groups[ls.lights[i].group].isVpl; };
  std::vector<size_t> first(blocks + 1, 0);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    for (size_t i = b * kBlock; i < std::min(ls.lights.size(), (b + 1) * kBlock); ++i) first[b + 1] += isVpl(i);
  });
  for (size_t b = 0; b < blocks; ++b) first[b + 1] += first[b];
  std::vector<uint32_t> vpls(first[blocks]);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    size_t at = first[b];
    for (size_t i = b * kBlock; i < std::min(ls.lights.size(), (b + 1) * kBlock); ++i)
      if (isVpl(i)) vpls[at++] = uint32_t(i);
  });
  if (vpls.empty()) return 0;
  // At each of `points` points, every VPL, or when that would exceed maxEvaluations an
  // evenly strided subset (every stride-th of the light array, from an offset of the
  // point's own; the VPLs lie there by cells of space, lights/vpl.cpp, so the subset is
  // spread evenly over space). The clamped share is dominated by the few VPLs nearest each
  // point, which any subset catches or misses: against every VPL at every point (Cornell
  // box, 256²), 1.24% for an exact 1.01% at 1M paths and 1.42% for 1.01% at 10M (the same
  // stride in path order gave 0.87% and 0.94%, random subsets 0.64% and 0.52%). Still, many
  // points with a subset each estimate it far better than a few with all: at 813,502 VPLs, 256
  // points with all of them gave 2.63%, 19 points with all 6.66%, 256 points with every
  // 53rd 2.48%. (At 10M VPL paths, 16 points with all 8.1M VPLs took about 8 s.)
  const uint64_t budget = std::max<uint64_t>(maxEvaluations, 1);
  const int k = std::max(points, 1);
  const size_t stride = size_t(std::max<uint64_t>(1, (uint64_t(k) * vpls.size() + budget - 1) / budget));
  auto px = referencePixelSet(k, o.width, o.height);
  std::vector<double> clamped(px.size(), 0), unclamped(px.size(), 0);
  tbb::parallel_for(size_t(0), px.size(), [&](size_t i) {
    const scene::Camera& cam = scene.camera();
    Vec3 d = normalize(cam.direction((float(px[i].first) + 0.5f) / float(o.width),
                                     (float(px[i].second) + 0.5f) / float(o.height)));
    scene::Hit h;
    if (!scene.intersect(scene::Ray{cam.eye, d, 0, kInf}, h)) return;
    scene::ShadingMaterial m = scene.shadingMaterial(h);
    if (isBlack(m.kd)) return;
    lightcuts::ShadingPoint sp;
    sp.p = h.p;
    sp.n = h.ns;
    sp.r = normalize(reflect(-d, h.ns));
    sp.kd = m.kd;
    ShadowRays vis(scene, h);
    for (size_t j = i * 7919 % stride; j < vpls.size(); j += stride) {
      const Light& l = ls.lights[vpls[j]];
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

}  // namespace lc::render
