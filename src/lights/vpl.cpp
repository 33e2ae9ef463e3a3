// Instant radiosity (Keller 1997).
//
// Units. The course's Phong model gives kd * cos / d^2 per unit point-light intensity, which
// is pi times physical radiance (its kd is an albedo, not kd/pi). A path that leaves light
// L with probability P_L, in a direction drawn with density p(w), carries the flux
//     Phi = I_L * G_L(w) * atten(d) * d^2 / (p(w) * P_L * N)
// to its first hit at distance d (G_L: 1 for omni, the cosine for surface lights, the
// falloff for spots; atten(d) d^2 is 1 for physical 1/d^2 lights and honours the course's
// other attenuation models). A diffuse hit with albedo kd reflects Phi * kd and leaves a
// VPL: an oriented light with intensity Phi * kd / pi facing along the shading normal, so
// that I cos(theta)/d^2 * kd' cos(theta') at a receiver is again pi times radiance.
// Later bounces (--bounces > 1) continue with cosine sampling (throughput kd) and Russian
// roulette (survival probability max(kd)).
//
// Directions: omni lights uniformly over the sphere; surface lights cosine-weighted about
// their normal; spot lights uniformly within their cone, weighted by the falloff;
// directional lights from a disk covering the scene's bounding sphere.
//
// Clamping. VPLs use atten(d) = min(1/dc^2, 1/d^2), dc = clamp * (scene diagonal / 2):
// written as the course attenuation min(1, 1/(c d^2)) with c = 1/dc^2 on an intensity
// scaled by 1/dc^2. Brute force, the Lightcuts estimate and its bounds all evaluate the
// same attenuation, so the clamp is identical in all three by construction.
//
// Normalisation "object" (the seed's): a VPL gets the scene's total light intensity times
// the diffuse colour at its hit, divided by the number of VPLs on the object it landed on.
#include "lights/vpl.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "core/memory_budget.h"
#include "core/rng.h"

namespace lc::lights {

namespace {

struct Deposit {
  Vec3 position, normal;
  Color flux;      // reflected flux Phi * kd
  Color kd;        // diffuse colour at the hit (object normalisation)
  int shape = -1;
};

Vec3 uniformSphere(float u1, float u2) {
  float z = 1 - 2 * u1, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * kPi * u2;
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

Vec3 aroundAxis(const Vec3& axis, float cosT, float phi) {
  Vec3 u, v;
  orthonormalBasis(axis, u, v);
  float sinT = std::sqrt(std::max(0.0f, 1 - cosT * cosT));
  return normalize(u * (sinT * std::cos(phi)) + v * (sinT * std::sin(phi)) + axis * cosT);
}

Vec3 cosineHemisphere(const Vec3& n, float u1, float u2) {
  return aroundAxis(n, std::sqrt(1 - u1), 2 * kPi * u2);
}

// The widest angle a spot light emits into (cutoff, or the smooth cone's edge).
float spotCosMax(const SpotFalloff& f) { return std::max(f.cosCutoff, f.cosOuter > -2 ? f.cosOuter : -1.0f); }

// Emitted power (luminance) used to share the paths among the lights.
double lightPower(const Light& l, const LightGroup& g, float sceneRadius) {
  double I = luminance(l.intensity);
  switch (l.type) {
    case LightType::Omni: return 4 * kPi * I;
    case LightType::Oriented: return kPi * I;
    case LightType::Directional: return kPi * double(sceneRadius) * sceneRadius * I;
    case LightType::Spot: {
      // 2 pi * integral of the falloff over cos in [-1, 1] (midpoint rule).
      double s = 0;
      constexpr int kSteps = 256;
      for (int i = 0; i < kSteps; ++i) s += g.falloff(-1 + 2 * (float(i) + 0.5f) / kSteps);
      return 2 * kPi * s * 2.0 / kSteps * I;
    }
  }
  return 0;
}

}  // namespace

EmissionSampler::EmissionSampler(const scene::Scene& scene, const LightSet& set, std::vector<Light> sources)
    : set_(set), sources_(std::move(sources)), eps_(scene.epsilon()) {
  const Bounds3& bounds = scene.bounds();
  radius_ = std::max(1e-6f, bounds.diagonal() * 0.5f);
  centre_ = bounds.center();
  cdf_.assign(sources_.size() + 1, 0.0);
  for (size_t i = 0; i < sources_.size(); ++i)
    cdf_[i + 1] = cdf_[i] + lightPower(sources_[i], set_.groups[sources_[i].group], radius_);
  total_ = cdf_.back();
}

EmissionSampler::Sample EmissionSampler::sample(Rng& rng, size_t n) const {
  double u = rng.uniformDouble() * total_;
  size_t li = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin()) - 1;
  li = std::min(li, sources_.size() - 1);
  while (li > 0 && cdf_[li + 1] == cdf_[li]) --li;  // never pick a zero-power light
  const Light& L = sources_[li];
  const LightGroup& g = set_.groups[L.group];
  double pL = (cdf_[li + 1] - cdf_[li]) / total_;
  Sample s;
  s.light = &L;
  s.group = &g;
  Vec3& origin = s.origin;
  Vec3& dir = s.dir;
  float weight = 0;  // G(w) / p(w)
  switch (L.type) {
    case LightType::Omni:
      origin = L.position;
      dir = uniformSphere(rng.uniform(), rng.uniform());
      weight = 4 * kPi;
      break;
    case LightType::Oriented:
      dir = cosineHemisphere(L.direction, rng.uniform(), rng.uniform());
      origin = L.position + L.direction * eps_;
      weight = kPi;
      break;
    case LightType::Spot: {
      float cosMax = spotCosMax(g.falloff);
      float c = 1 - rng.uniform() * (1 - cosMax);
      dir = aroundAxis(L.direction, c, 2 * kPi * rng.uniform());
      origin = L.position;
      weight = g.falloff(c) * 2 * kPi * (1 - cosMax);
      break;
    }
    case LightType::Directional: {
      dir = L.direction;
      Vec3 a, bb;
      orthonormalBasis(dir, a, bb);
      float r = radius_ * std::sqrt(rng.uniform()), phi = 2 * kPi * rng.uniform();
      origin = centre_ - dir * (2 * radius_) + a * (r * std::cos(phi)) + bb * (r * std::sin(phi));
      weight = kPi * radius_ * radius_;
      break;
    }
  }
  s.flux = L.intensity * float(double(weight) / (pL * double(n)));
  return s;
}

float EmissionSampler::Sample::firstHit(float t) const {
  return light->type == LightType::Directional ? 1.0f : group->atten(t) * t * t;
}

VplInfo addVpls(scene::Scene& scene, const VplOptions& o) {
  auto t0 = std::chrono::steady_clock::now();
  if (o.count < 0) throw Error("--vpls must be >= 0");
  if (uint64_t(o.count) > o.maxVpls)
    throw Error(fmt::format("{} VPL paths requested, more than --max-vpls ({})", o.count, o.maxVpls));
  if (o.bounces < 0) throw Error("--bounces must be >= 0");
  // Each path deposits at most one VPL per bounce: bound the memory before shooting.
  if (uint64_t(o.count) * uint64_t(std::max(o.bounces, 1)) > 4 * o.maxVpls)
    throw Error(fmt::format("{} paths with {} bounces could deposit more than --max-vpls ({}) VPLs", o.count,
                            o.bounces, o.maxVpls));
  if (!std::isfinite(o.clamp) || o.clamp < 0) throw Error("the VPL clamp must be a finite number >= 0");
  VplInfo info;
  if (o.count == 0 || o.bounces == 0) return info;
  // Each path leaves at least one VPL in a closed scene: count those before shooting, the
  // rest (further bounces) once they are known.
  uint64_t reserved = uint64_t(o.count) * memory_cost::kLight;
  processBudget().reserve(reserved, fmt::format("{} VPLs", o.count));

  LightSet& set = scene.lights();
  const std::vector<Light> sources(set.lights.begin(), set.lights.end());  // VPLs are not sources themselves
  float radius = std::max(1e-6f, scene.bounds().diagonal() * 0.5f);

  EmissionSampler emission(scene, set, sources);
  if (!emission.hasPower()) return info;

  // Paths in blocks; each block's deposits are kept in path order, so the VPLs do not
  // depend on thread timing.
  const size_t n = size_t(o.count);
  constexpr size_t kBlock = 1024;
  size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<Deposit>> out(blocks);
  Progress progress(o.progress, double(n));
  auto cancelled = [&] { return o.cancel && o.cancel->load(std::memory_order_relaxed); };
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    if (cancelled()) return;
    std::vector<Deposit>& dep = out[b];
    // Room for a VPL per path, its pages faulted in with one call (core/huge_pages.h) rather
    // than a trap each: grown from empty, the deposits were half the process's page faults
    // at 10M paths (perf), each copied on the way.
    dep.reserve(kBlock);
    prefault(dep.data(), kBlock * sizeof(Deposit));
    for (size_t p = b * kBlock; p < std::min(n, (b + 1) * kBlock); ++p) {
      Rng rng(o.seed, p);
      EmissionSampler::Sample e = emission.sample(rng, n);
      Vec3 origin = e.origin, dir = e.dir;
      Color flux = e.flux;
      bool first = true;
      for (int bounce = 1; bounce <= o.bounces; ++bounce) {
        scene::Hit h;
        if (!scene.intersect(scene::Ray{origin, dir, 0, kInf}, h)) break;
        if (first) flux *= e.firstHit(h.t);
        first = false;
        Color kd = scene.shadingMaterial(h).kd;
        if (isBlack(kd) || !isFinite(flux)) break;  // no diffuse surface, no VPL
        dep.push_back(Deposit{h.p, h.ns, flux * kd, kd, h.shape});
        if (bounce == o.bounces) break;
        float q = std::min(1.0f, maxComponent(kd));
        if (rng.uniform() >= q) break;
        flux = flux * kd / q;
        dir = cosineHemisphere(h.ns, rng.uniform(), rng.uniform());
        origin = scene.offsetOrigin(h, dir);
      }
    }
    progress.add(double(std::min(n, (b + 1) * kBlock) - b * kBlock));
  });
  progress.finish();
  if (cancelled()) throw Interrupted();

  size_t count = 0;
  for (const auto& d : out) count += d.size();
  if (count > o.maxVpls) throw Error(fmt::format("{} VPLs exceed --max-vpls ({})", count, o.maxVpls));
  if (count >= (uint64_t(1) << 32)) throw Error(fmt::format("{} VPLs: more than a light set can index", count));
  if (uint64_t(count) * memory_cost::kLight > reserved)
    processBudget().reserve(uint64_t(count) * memory_cost::kLight - reserved, fmt::format("{} VPLs", count));

  LightGroup vg;
  vg.diffuseOnly = true;
  vg.isVpl = true;
  float scale = 1;
  info.clampDistance = o.clamp * radius;
  if (info.clampDistance > 0) {
    vg.atten = Attenuation{0, 0, 1 / (info.clampDistance * info.clampDistance), kInf};
    scale = 1 / (info.clampDistance * info.clampDistance);
  } else {
    vg.atten = Attenuation{0, 0, 1, kInf};
  }
  uint16_t group = set.groupFor(vg);

  std::vector<uint32_t> perShape(scene.shapes().size(), 0);
  if (o.normalize == VplNormalize::Object)
    for (const auto& d : out)
      for (const Deposit& v : d) ++perShape[size_t(v.shape)];
  Color sceneIntensity(0);
  for (const Light& l : sources) sceneIntensity += l.intensity;

  // The power summed per block in path order, then over the blocks in order, so that it
  // does not depend on the thread count.
  auto intensityOf = [&](const Deposit& v) {
    return o.normalize == VplNormalize::Object ? sceneIntensity * v.kd / float(perShape[size_t(v.shape)])
                                               : v.flux / kPi;
  };
  std::vector<Vec3d> blockPower(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    Vec3d sum;  // over millions of VPLs: in double
    for (const Deposit& v : out[b]) sum += o.normalize == VplNormalize::Object ? intensityOf(v) * kPi : v.flux;
    blockPower[b] = sum;
  });
  Vec3d power;
  for (const Vec3d& p : blockPower) power += p;
  // The lights by cells of space, in the cells' Morton order, each cell's in path order: a
  // counting sort on the top kCellBits bits of each deposit's Morton code (32,768 cells of
  // the scene's box). The light tree's leaves are then neighbours in the light array too:
  // its build reads each bottom-up group's lights from a few lines instead of scattered
  // ones, and a cut finds the representatives of a subtree's clusters close together (in
  // path order, each was a cache miss). The paths are counted and written in kChunks fixed
  // chunks, in parallel: each chunk writes its part of each cell, so the order does not
  // depend on the thread count.
  constexpr int kCellBits = 15;
  constexpr size_t kCells = size_t(1) << kCellBits, kChunks = 16;
  const Bounds3 where = scene.bounds();  // every deposit lies on the scene's surfaces
  auto cellOf = [&](const Deposit& v) { return mortonCode(v.position, where) >> (30 - kCellBits); };
  const size_t blocksPerChunk = (blocks + kChunks - 1) / kChunks;
  std::vector<uint32_t> at(kChunks * kCells, 0);  // per chunk and cell: a count, then where it writes
  tbb::parallel_for(size_t(0), kChunks, [&](size_t c) {
    uint32_t* n = &at[c * kCells];
    for (size_t b = c * blocksPerChunk; b < std::min(blocks, (c + 1) * blocksPerChunk); ++b)
      for (const Deposit& v : out[b]) ++n[cellOf(v)];
  });
  uint32_t next = 0;
  for (size_t cell = 0; cell < kCells; ++cell)
    for (size_t c = 0; c < kChunks; ++c) next += std::exchange(at[c * kCells + cell], next);
  // Written in parallel (one thread took 0.7 s for 8.1M of them at 10M paths, the light
  // array's page faults included).
  const size_t base = set.lights.size();
  set.lights.reserve(base + count);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, size_t(1) << 18), [&](const tbb::blocked_range<size_t>& r) {
    prefault(set.lights.data() + base + r.begin(), r.size() * sizeof(Light));
  });
  set.lights.resize(base + count);
  tbb::parallel_for(size_t(0), kChunks, [&](size_t c) {
    uint32_t* dst = &at[c * kCells];
    for (size_t b = c * blocksPerChunk; b < std::min(blocks, (c + 1) * blocksPerChunk); ++b)
      for (const Deposit& v : out[b]) {
        Light l;
        l.type = LightType::Oriented;
        l.group = group;
        l.position = v.position;
        l.direction = v.normal;
        l.intensity = intensityOf(v) * scale;
        set.lights[base + dst[cellOf(v)]++] = l;
      }
  });
  // The deposits (52 bytes per VPL, in blocks of a thousand) go back to the system now: freed
  // blocks of that size stay in the allocator's per-thread arenas, where the light tree's
  // large arrays cannot reuse them (at 10M paths, 245 MB held through the tree build).
  std::vector<std::vector<Deposit>>().swap(out);
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
  info.power = power.toFloat();
  info.paths = n;
  info.vpls = count;
  info.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return info;
}

}  // namespace lc::lights
