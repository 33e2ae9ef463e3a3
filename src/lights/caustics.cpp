// Caustics as many lights: see caustics.h for the model and its units.
#include "lights/caustics.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "core/error.h"
#include "core/rng.h"
#include "lights/vpl.h"

namespace lc::lights {

namespace {

// Caustic paths draw from streams apart from the VPLs' (which use (seed, path) with path < 2^63).
constexpr uint64_t kStreamOffset = uint64_t(1) << 63;

float mean(const Color& c) { return std::max(0.0f, (c.x + c.y + c.z) / 3); }

// The distance from each point to its k-th nearest other point: a k-d tree over the points
// (median splits, axes in turn), queried with a bounded max-heap. Deterministic.
class KthNearest {
 public:
  explicit KthNearest(const std::vector<Vec3>& pts) : pts_(pts), idx_(pts.size()), axis_(pts.size(), 0) {
    for (uint32_t i = 0; i < idx_.size(); ++i) idx_[i] = i;
    build(0, idx_.size(), 0);
  }
  float distance(uint32_t self, int k) const {
    std::vector<float> heap;  // the k smallest squared distances, as a max-heap
    heap.reserve(size_t(k) + 1);
    query(0, idx_.size(), pts_[self], self, size_t(k), heap);
    if (heap.empty()) return 0;
    return std::sqrt(heap.front());
  }

 private:
  static constexpr size_t kLeaf = 8;
  void build(size_t lo, size_t hi, int depth) {
    if (hi - lo <= kLeaf) return;
    size_t mid = (lo + hi) / 2;
    int a = depth % 3;
    std::nth_element(idx_.begin() + long(lo), idx_.begin() + long(mid), idx_.begin() + long(hi),
                     [&](uint32_t x, uint32_t y) { return pts_[x][a] < pts_[y][a] || (pts_[x][a] == pts_[y][a] && x < y); });
    axis_[mid] = uint8_t(a);
    build(lo, mid, depth + 1);
    build(mid + 1, hi, depth + 1);
  }
  void consider(uint32_t i, const Vec3& p, uint32_t self, size_t k, std::vector<float>& heap) const {
    if (i == self) return;
    float d2 = length2(pts_[i] - p);
    if (heap.size() < k) {
      heap.push_back(d2);
      std::push_heap(heap.begin(), heap.end());
    } else if (d2 < heap.front()) {
      std::pop_heap(heap.begin(), heap.end());
      heap.back() = d2;
      std::push_heap(heap.begin(), heap.end());
    }
  }
  void query(size_t lo, size_t hi, const Vec3& p, uint32_t self, size_t k, std::vector<float>& heap) const {
    if (hi - lo <= kLeaf) {
      for (size_t i = lo; i < hi; ++i) consider(idx_[i], p, self, k, heap);
      return;
    }
    size_t mid = (lo + hi) / 2;
    uint32_t m = idx_[mid];
    int a = axis_[mid];
    consider(m, p, self, k, heap);
    float diff = p[a] - pts_[m][a];
    bool left = diff < 0;
    if (left) query(lo, mid, p, self, k, heap);
    else query(mid + 1, hi, p, self, k, heap);
    if (heap.size() < k || diff * diff < heap.front()) {
      if (left) query(mid + 1, hi, p, self, k, heap);
      else query(lo, mid, p, self, k, heap);
    }
  }
  const std::vector<Vec3>& pts_;
  std::vector<uint32_t> idx_;
  std::vector<uint8_t> axis_;
};

}  // namespace

std::vector<Light> causticSources(const LightSet& set) {
  std::vector<Light> out;
  for (const Light& l : set.lights)
    if (!set.groups[l.group].isVpl) out.push_back(l);
  return out;
}

std::vector<CausticHit> traceCausticPaths(const scene::Scene& scene, const std::vector<Light>& sources, size_t n,
                                          uint64_t seed, int maxSpecular, const ProgressFn& progressFn,
                                          const std::atomic<bool>* cancel) {
  std::vector<CausticHit> all;
  if (n == 0 || sources.empty()) return all;
  EmissionSampler emission(scene, scene.lights(), sources);
  if (!emission.hasPower()) return all;
  constexpr size_t kBlock = 4096;
  size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<CausticHit>> out(blocks);
  Progress progress(progressFn, double(n));
  auto cancelled = [&] { return cancel && cancel->load(std::memory_order_relaxed); };
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    if (cancelled()) return;
    std::vector<CausticHit>& dep = out[b];
    for (size_t p = b * kBlock; p < std::min(n, (b + 1) * kBlock); ++p) {
      Rng rng(seed, kStreamOffset | p);
      EmissionSampler::Sample e = emission.sample(rng, n);
      Vec3 origin = e.origin, dir = e.dir, from;
      Color flux = e.flux;
      for (int depth = 0; depth <= maxSpecular; ++depth) {
        scene::Hit h;
        if (!scene.intersect(scene::Ray{origin, dir, 0, kInf}, h)) break;
        if (depth == 0) flux *= e.firstHit(h.t);
        if (!isFinite(flux)) break;
        scene::ShadingMaterial m = scene.shadingMaterial(h);
        if (depth > 0 && !isBlack(m.kd)) dep.push_back(CausticHit{h.p, h.ns, from, flux, h.shape});
        if (depth == maxSpecular) break;
        // Reflect or refract, as camera rays do, chosen in proportion to kr and kt, with
        // Russian roulette when they sum below 1; the weight k / probability keeps the
        // estimate unbiased (it is 1 for grey kr + kt <= 1).
        float pr = mean(m.kr), pt = mean(m.kt), s = pr + pt;
        if (!(s > 0)) break;
        float q = std::min(1.0f, s);
        float u = rng.uniform();
        if (u >= q) break;
        Vec3 v = -normalize(dir), nd;
        Color k;
        float prob;
        if (u < q * pr / s) {
          nd = normalize(reflect(v, h.ns));
          k = m.kr;
          prob = q * pr / s;
        } else {
          // renderer.cpp's refraction: entering through the front face goes from air into the material.
          float eta = h.frontFace ? 1.0f / m.ior : m.ior;
          float cosI = std::min(1.0f, dot(v, h.ns));
          float sin2T = eta * eta * (1 - cosI * cosI);
          if (!(sin2T < 1)) nd = normalize(reflect(v, h.ns));  // total internal reflection
          else nd = normalize(-v * eta + h.ns * (eta * cosI - std::sqrt(1 - sin2T)));
          k = m.kt;
          prob = q * pt / s;
        }
        if (!isFinite(nd)) break;
        flux = flux * k / prob;
        origin = scene.offsetOrigin(h, nd);
        from = origin;
        dir = nd;
      }
    }
    progress.add(double(std::min(n, (b + 1) * kBlock) - b * kBlock));
  });
  progress.finish();
  if (cancelled()) throw Interrupted();
  size_t count = 0;
  for (const auto& d : out) count += d.size();
  all.reserve(count);
  for (auto& d : out) all.insert(all.end(), d.begin(), d.end());
  return all;
}

CausticInfo addCaustics(scene::Scene& scene, const CausticOptions& o) {
  auto t0 = std::chrono::steady_clock::now();
  if (o.paths < 0) throw Error("--caustics must be >= 0");
  if (o.maxSpecularBounces < 1) throw Error("caustic paths need at least one specular bounce");
  if (o.neighbours < 1) throw Error("the caustic neighbour count must be >= 1");
  if (!std::isfinite(o.smoothing) || !(o.smoothing > 0)) throw Error("the caustic smoothing must be a finite number > 0");
  CausticInfo info;
  info.kind = o.kind;
  if (o.paths == 0) return info;
  scene.setShadowsThroughGlass(false);
  LightSet& set = scene.lights();
  std::vector<CausticHit> hits =
      traceCausticPaths(scene, causticSources(set), size_t(o.paths), o.seed, o.maxSpecularBounces, o.progress, o.cancel);
  info.paths = uint64_t(o.paths);
  if (hits.size() > o.maxLights)
    throw Error(fmt::format("{} caustic lights exceed --max-lights ({})", hits.size(), o.maxLights));

  // Each light's footprint R from its k-th nearest neighbouring hit.
  const float sceneRadius = std::max(1e-6f, scene.bounds().diagonal() * 0.5f);
  const float minR = 1e-4f * sceneRadius, maxR = 0.1f * sceneRadius;
  std::vector<float> R(hits.size());
  {
    std::vector<Vec3> pts(hits.size());
    for (size_t i = 0; i < hits.size(); ++i) pts[i] = hits[i].position;
    KthNearest knn(pts);
    int k = std::min<int>(o.neighbours, int(std::max<size_t>(1, hits.size() - 1)));
    tbb::parallel_for(size_t(0), hits.size(), [&](size_t i) {
      float r = hits.size() > 1 ? knn.distance(uint32_t(i), k) : maxR;
      R[i] = std::clamp(o.smoothing * r, minR, maxR);
      // A vpl light is lifted R off its surface: never into or past what lies above it
      // (under a ball lens, the ball).
      if (o.kind == CausticLightKind::Vpl) {
        const CausticHit& c = hits[i];
        float t;
        Vec3 org = c.position + c.normal * scene.epsilon();
        if (scene.firstHit(org, c.normal, R[i] * 2, t) >= 0) R[i] = std::max(minR, 0.5f * t);
      }
    });
  }

  // The attenuation min(1, 1/(c d^2)) with c = 1/dc^2 on intensities scaled by 1/dc^2
  // (as the VPLs' clamp): exactly 1/d^2 beyond dc, whatever the scene's units.
  float dc = maxR;
  for (size_t i = 0; i < hits.size(); ++i) {
    float d = o.kind == CausticLightKind::Vpl ? R[i] : length(hits[i].position - hits[i].from);
    dc = std::min(dc, 0.5f * std::max(d, minR));
  }
  const float scale = 1 / (dc * dc);
  LightGroup base;
  base.diffuseOnly = true;  // a caustic lights the diffuse term (its splat has no highlight)
  base.atten = Attenuation{0, 0, scale, kInf};

  std::map<int, uint16_t> spotGroups;  // log2 exponent -> group
  uint16_t vplGroup = o.kind == CausticLightKind::Vpl ? set.groupFor(base) : 0;
  const size_t first = set.lights.size();
  set.lights.reserve(first + hits.size());
  Vec3d power, radii;
  for (size_t i = 0; i < hits.size(); ++i) {
    const CausticHit& c = hits[i];
    Light l;
    if (o.kind == CausticLightKind::Vpl) {
      l.type = LightType::Oriented;
      l.group = vplGroup;
      l.position = c.position + c.normal * R[i];
      l.direction = -c.normal;
      l.intensity = c.flux * (scale / kPi);
    } else {
      Vec3 d = c.position - c.from;
      float D = length(d);
      if (!(D > 0)) continue;
      // cos^e ~ exp(-e theta^2 / 2): a Gaussian of angular sigma 1/sqrt(e); half its light
      // within 1.177 sigma.
      float sigma = std::min(1.0f, R[i] / (1.1774f * D));
      int lg = std::clamp(int(std::lround(std::log2(1 / (sigma * sigma)))), 0, 24);
      auto it = spotGroups.find(lg);
      if (it == spotGroups.end()) {
        LightGroup g = base;
        g.falloff = SpotFalloff{float(1 << lg), 0.0f, -2, -2};
        it = spotGroups.emplace(lg, set.groupFor(g)).first;
      }
      float e = float(1 << lg);
      l.type = LightType::Spot;
      l.group = it->second;
      l.position = c.from;
      l.direction = d / D;
      l.intensity = c.flux * (scale * (e + 1) / (2 * kPi));
    }
    power += c.flux;
    radii += Vec3(R[i]);
    set.lights.push_back(l);
  }
  info.lights = set.lights.size() - first;
  info.power = power.toFloat();
  info.meanRadius = hits.empty() ? 0 : float(radii.x / double(hits.size()));
  info.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return info;
}

std::vector<Color> causticIrradiance(const std::vector<CausticHit>& hits, const std::vector<Vec3>& points,
                                     const std::vector<Vec3>& normals, float radius) {
  std::vector<Color> out(points.size(), Color(0));
  const float r2 = radius * radius, norm = 1 / (kPi * r2);
  tbb::parallel_for(size_t(0), points.size(), [&](size_t j) {
    Vec3d sum;
    for (const CausticHit& h : hits)
      if (length2(h.position - points[j]) <= r2 && dot(h.normal, normals[j]) > 0.5f) sum += h.flux;
    out[j] = sum.toFloat() * norm;
  });
  return out;
}

}  // namespace lc::lights
