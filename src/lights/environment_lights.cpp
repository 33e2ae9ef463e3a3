#include "lights/environment_lights.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/error.h"
#include "core/rng.h"

namespace lc::lights {

namespace {

// A pixel of less solid angle than this (4 pi / 4,096 sr, the average share of the default
// 4,096 lights; a 3.2 degree square) is whole: lights drawn in it are merged into one, and
// one that holds kOwnLightShares shares or more becomes one light of its own. Its radiance is
// constant, so lights within it would differ only in direction, and a map's one-pixel sun
// would otherwise become thousands of nearly parallel lights that every point in its shadow
// must test. The bound does not depend on N (it did once: 4 pi / N), so a pixel is treated
// the same at every N and the lights converge as N grows (docs/BENCHMARKS.md, "Convergence").
constexpr double kWholePixelSolidAngle = 4 * kPi / 4096;
// A whole pixel worth this many lights' shares (luminance x solid angle >= 8 S / N) is one
// light carrying its exact power at its centroid, instead of as many draws as the point set
// happens to put in it (its share count +- the set's discrepancy, a few draws: an error
// every point that sees the sun would share). Measured against 1 (every pixel worth a
// share): 8 keeps the sky's pixels out of it up to 65,536 lights, where at 1 the pixels
// taken out of the draws change with N and cost accuracy near the reference.
constexpr double kOwnLightShares = 8;

// The index i with cdf[i] <= x < cdf[i + 1] among entries of non-zero width.
size_t findInterval(const std::vector<double>& cdf, double x) {
  size_t i = size_t(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin());
  i = i == 0 ? 0 : i - 1;
  i = std::min(i, cdf.size() - 2);
  while (i > 0 && cdf[i + 1] == cdf[i]) --i;               // never a zero-weight entry
  while (i + 2 < cdf.size() && cdf[i + 1] == cdf[i]) ++i;  // (the first one may be)
  return i;
}

uint32_t reverseBits(uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  return ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
}

// The second dimension of Sobol's sequence, as a 32-bit fraction. With the van der Corput
// sequence (the first) it is a (0,2)-sequence in base 2: every aligned block of 2^m points
// is a (0,m,2)-net, each of the 2^m dyadic boxes of area 2^-m, of any shape, holding one.
uint32_t sobol2(uint32_t k) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; k; k >>= 1, v ^= v >> 1)
    if (k & 1) r ^= v;
  return r;
}

// Owen's nested uniform scrambling of a 32-bit fraction, hash-based (Burley 2020, "Practical
// hash-based Owen scrambling", after Laine and Karras 2011): each bit is flipped by a hash of
// the bits above it and the seed. A scrambled net is still a net, but no longer a lattice.
uint32_t owenScramble(uint32_t x, uint32_t seed) {
  x = reverseBits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverseBits(x);
}

// The integral of sqrt(1 - z^2) dz.
double sinIntegral(double z) {
  return 0.5 * (z * std::sqrt(std::max(0.0, 1 - z * z)) + std::asin(std::clamp(z, -1.0, 1.0)));
}

}  // namespace

void sampleEnvironment(const scene::Environment& env, int count, uint64_t seed, std::vector<Vec3>& toLight,
                       std::vector<Color>& intensity, Progress* progress) {
  toLight.clear();
  intensity.clear();
  const io::Image& t = env.table();
  const int W = t.width, H = t.height;
  if (count <= 0 || W <= 0 || H <= 0) return;
  std::vector<double> cosEdge(size_t(H) + 1), omega(static_cast<size_t>(H));
  for (int j = 0; j <= H; ++j) cosEdge[size_t(j)] = std::cos(kPi * double(j) / H);
  double S = 0;  // luminance x solid angle over the sphere
  for (int j = 0; j < H; ++j) {
    omega[size_t(j)] = 2 * kPi / W * (cosEdge[size_t(j)] - cosEdge[size_t(j) + 1]);
    double row = 0;
    for (int i = 0; i < W; ++i) row += std::max(0.0f, luminance(t.at(i, j)));
    S += row * omega[size_t(j)];
  }
  if (!(S > 0)) return;  // a black environment gives no light
  const double share = S / count;  // one light's share
  // Pixels of their own (above) first, each taking floor(power / share) of the N lights.
  // Then the weights of the rest: luminance x solid angle, those pixels left out; rows'
  // cumulative sums (double: a 16k map has 2^27 pixels), and the marginal over rows.
  std::vector<double> rowCdf(size_t(H) + 1, 0.0);
  std::vector<std::vector<double>> colCdf(static_cast<size_t>(H));
  int64_t taken = 0;
  for (int j = 0; j < H; ++j) {
    const double om = omega[size_t(j)];
    const bool whole = om < kWholePixelSolidAngle;
    std::vector<double>& c = colCdf[size_t(j)];
    c.assign(size_t(W) + 1, 0.0);
    for (int i = 0; i < W; ++i) {
      Color L = t.at(i, j);
      double w = std::max(0.0f, luminance(L)) * om;
      if (whole && w >= kOwnLightShares * share) {
        // At the centroid: the middle column, and the elevation of the mean unit vector over
        // the pixel (horizontal part 2 sin(dphi / 2) x the integral of sqrt(1 - z^2) dz,
        // vertical part dphi x the integral of z dz).
        double z0 = cosEdge[size_t(j) + 1], z1 = cosEdge[size_t(j)], dphi = 2 * kPi / W;
        double v = std::atan2(2 * std::sin(dphi / 2) * (sinIntegral(z1) - sinIntegral(z0)),
                              dphi * 0.5 * (z1 * z1 - z0 * z0)) / kPi;
        toLight.push_back(env.direction((i + 0.5) / W, v));
        intensity.push_back(vmax(L, Color(0)) * float(om / kPi));
        taken += int64_t(w / share);
        w = 0;
      }
      c[size_t(i) + 1] = c[size_t(i)] + w;
    }
    rowCdf[size_t(j) + 1] = rowCdf[size_t(j)] + c.back();
  }
  const double rest = rowCdf.back();
  // The floors sum to at most N (1 - rest / S): while any of the map is left, so is a light.
  const int n = int(std::max<int64_t>(count - taken, 0));
  if (progress) progress->add(double(count - n));
  if (!(rest > 0) || n == 0) return;
  Rng rng(seed, 0x656e766972ull);
  const uint32_t scramble1 = rng.next(), scramble2 = rng.next();
  const double perLight = rest / (double(n) * kPi);  // every drawn light's luminance
  toLight.reserve(toLight.size() + size_t(n));
  intensity.reserve(intensity.size() + size_t(n));
  // Draws that land in the same whole pixel become one light (summed intensity, mean direction).
  std::unordered_map<size_t, size_t> merged;  // pixel -> index of its light
  std::vector<Vec3d> dirSum(toLight.size());
  for (int k = 0; k < n; ++k) {
    // The Sobol' (0,2)-sequence, Owen-scrambled by the seed; the middle of the point's
    // 2^-32 cell.
    double u1 = (double(owenScramble(reverseBits(uint32_t(k)), scramble1)) + 0.5) * 0x1p-32;
    double u2 = (double(owenScramble(sobol2(uint32_t(k)), scramble2)) + 0.5) * 0x1p-32;
    size_t j = findInterval(rowCdf, u1 * rest);
    double rowW = rowCdf[j + 1] - rowCdf[j];
    double f1 = std::clamp((u1 * rest - rowCdf[j]) / rowW, 0.0, 1.0);
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
    if (omega[j] < kWholePixelSolidAngle) {
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
