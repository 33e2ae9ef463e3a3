#include "lights/environment_lights.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/error.h"
#include "core/rng.h"

namespace lc::lights {

namespace {

// The index i with cdf[i] <= x < cdf[i + 1] among entries of non-zero width.
size_t findInterval(const std::vector<double>& cdf, double x) {
  size_t i = size_t(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin());
  i = i == 0 ? 0 : i - 1;
  i = std::min(i, cdf.size() - 2);
  while (i > 0 && cdf[i + 1] == cdf[i]) --i;               // never a zero-weight entry
  while (i + 2 < cdf.size() && cdf[i + 1] == cdf[i]) ++i;  // (the first one may be)
  return i;
}

}  // namespace

void sampleEnvironment(const scene::Environment& env, int count, uint64_t seed, std::vector<Vec3>& toLight,
                       std::vector<Color>& intensity, Progress* progress) {
  toLight.clear();
  intensity.clear();
  const io::Image& t = env.table();
  const int W = t.width, H = t.height;
  if (count <= 0 || W <= 0 || H <= 0) return;
  // Pixel weights: luminance x solid angle; rows' cumulative sums (double: a 16k map has
  // 2^27 pixels), and the marginal over rows.
  std::vector<double> rowCdf(size_t(H) + 1, 0.0);
  std::vector<std::vector<double>> colCdf(static_cast<size_t>(H));
  std::vector<double> cosEdge(size_t(H) + 1);
  for (int j = 0; j <= H; ++j) cosEdge[size_t(j)] = std::cos(kPi * double(j) / H);
  for (int j = 0; j < H; ++j) {
    double omega = 2 * kPi / W * (cosEdge[size_t(j)] - cosEdge[size_t(j) + 1]);
    std::vector<double>& c = colCdf[size_t(j)];
    c.assign(size_t(W) + 1, 0.0);
    for (int i = 0; i < W; ++i) c[size_t(i) + 1] = c[size_t(i)] + std::max(0.0f, luminance(t.at(i, j))) * omega;
    rowCdf[size_t(j) + 1] = rowCdf[size_t(j)] + c.back();
  }
  const double S = rowCdf.back();
  if (!(S > 0)) return;  // a black environment gives no light
  Rng rng(seed, 0x656e766972ull);
  const double shift1 = rng.uniformDouble(), shift2 = rng.uniformDouble();
  const double perLight = S / (double(count) * kPi);  // every light's luminance
  toLight.reserve(size_t(count));
  intensity.reserve(size_t(count));
  // Lights that land in one pixel smaller than an average light's share of the sphere
  // (4 pi / N) become one light: the pixel's radiance is constant, so they differ only in
  // direction within the pixel. Keeps a one-pixel sun in a map from becoming thousands of
  // nearly parallel lights that a shadowed point must all test.
  const double mergeBelow = 4 * kPi / count;
  std::unordered_map<size_t, size_t> merged;  // pixel -> index of its light
  std::vector<Vec3d> dirSum;
  for (int k = 0; k < count; ++k) {
    // A Hammersley point, shifted modulo 1 (Cranley-Patterson).
    double u1 = (double(k) + 0.5) / count + shift1, u2 = double(radicalInverse2(uint32_t(k))) + shift2;
    u1 -= std::floor(u1);
    u2 -= std::floor(u2);
    size_t j = findInterval(rowCdf, u1 * S);
    double rowW = rowCdf[j + 1] - rowCdf[j];
    double f1 = std::clamp((u1 * S - rowCdf[j]) / rowW, 0.0, 1.0);
    const std::vector<double>& c = colCdf[j];
    size_t i = findInterval(c, u2 * c.back());
    double colW = c[i + 1] - c[i];
    double f2 = std::clamp((u2 * c.back() - c[i]) / colW, 0.0, 1.0);
    // Uniform in solid angle within the pixel: cos(theta) linear across the row's band.
    double cosT = cosEdge[j] + f1 * (cosEdge[j + 1] - cosEdge[j]);
    double v = std::acos(std::clamp(cosT, -1.0, 1.0)) / kPi;
    double u = (double(i) + f2) / W;
    Color L = t.at(int(i), int(j));
    double Y = luminance(L);
    Vec3 w = env.direction(u, v);
    Color I = L * float(perLight / Y);
    double omega = 2 * kPi / W * (cosEdge[j] - cosEdge[j + 1]);
    if (omega < mergeBelow) {
      auto [it, fresh] = merged.try_emplace(j * size_t(W) + i, toLight.size());
      if (!fresh) {
        size_t m = it->second;
        dirSum[m] += w;
        intensity[m] += I;
        toLight[m] = normalize(dirSum[m].toFloat());
        if (progress && (k & 1023) == 1023) progress->add(1024);
        continue;
      }
    }
    toLight.push_back(w);
    intensity.push_back(I);
    dirSum.push_back(Vec3d(w));
    if (progress && (k & 1023) == 1023) progress->add(1024);
  }
}

std::vector<EnvironmentLightInfo> addEnvironmentLights(scene::Scene& scene, const EnvironmentLightOptions& o) {
  std::vector<EnvironmentLightInfo> infos;
  const auto& envs = scene.environments();
  if (envs.empty()) return infos;
  uint64_t total = 0;
  for (const scene::Environment& e : envs) total += uint64_t(o.count ? *o.count : e.lights()) + (e.hasSun() ? 1 : 0);
  if (o.count && *o.count < 1) throw Error("--env-lights must be >= 1");
  if (total + scene.lights().size() > o.maxLights)
    throw Error(fmt::format("the environment's {} directional lights and the scene's {} lights exceed --max-lights ({})",
                            total, scene.lights().size(), o.maxLights));
  LightSet& set = scene.lights();
  LightGroup g;
  g.atten = Attenuation{0, 0, 0, kInf};  // as directional_light's
  uint16_t group = set.groupFor(g);
  Progress progress(o.progress, double(total));
  std::vector<Vec3> dirs;
  std::vector<Color> intensities;
  for (size_t ei = 0; ei < envs.size(); ++ei) {
    if (o.cancel && o.cancel->load()) throw Interrupted();
    const scene::Environment& e = envs[ei];
    EnvironmentLightInfo info;
    info.what = e.describe();
    int n = o.count ? *o.count : e.lights();
    sampleEnvironment(e, n, splitmix64(o.seed + ei), dirs, intensities, &progress);
    Vec3d power;
    for (size_t k = 0; k < dirs.size(); ++k) {
      if (isBlack(intensities[k]) || !isFinite(intensities[k])) continue;
      Light l;
      l.type = LightType::Directional;
      l.group = group;
      l.direction = -dirs[k];
      l.intensity = intensities[k];
      set.lights.push_back(l);
      power += intensities[k] * kPi;
      ++info.lights;
    }
    if (e.hasSun() && !isBlack(e.sunIrradiance())) {
      Light l;
      l.type = LightType::Directional;
      l.group = group;
      l.direction = e.sunTravel();
      l.intensity = e.sunIrradiance() / kPi;
      set.lights.push_back(l);
      power += e.sunIrradiance();
      ++info.lights;
    }
    info.power = power.toFloat();
    infos.push_back(info);
  }
  progress.finish();
  return infos;
}

}  // namespace lc::lights
