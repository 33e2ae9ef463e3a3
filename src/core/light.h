// The one light model every many-light method uses (brute force, Lightcuts, the seed's
// cuts). Header-only and free of parser/Embree dependencies so the lightcuts library can
// use it on its own.
//
// Kinds (intensity I is RGB, in the units of a .ray point_light colour):
//   Omni        point light, equal in all directions:     I * atten(d)
//   Oriented    point light on a surface (object lights, VPLs): I * max(cos theta, 0) * atten(d),
//               theta between `direction` (the surface normal) and the direction to the receiver
//   Spot        point light with a cone about `direction`:  I * falloff(cos theta) * atten(d)
//   Directional light from infinitely far, travelling along `direction`: I
// atten(d) is the course renderer's min(1, 1/(a + b d + c d^2)), zero beyond maxDistance.
// Lights that share attenuation, falloff and flags share a LightGroup; the light tree is
// built per (kind, group), so a cluster never mixes models and every bound stays exact.
#pragma once

#include <cmath>
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/huge_pages.h"
#include "core/math.h"

namespace lc {

enum class LightType : uint8_t { Omni = 0, Oriented = 1, Spot = 2, Directional = 3 };
constexpr int kLightTypeCount = 4;

inline const char* lightTypeName(LightType t) {
  switch (t) {
    case LightType::Omni: return "omni";
    case LightType::Oriented: return "oriented";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
  }
  return "?";
}

// min(1, 1/(a + b d + c d^2)); non-increasing in d for a, b, c >= 0, which is what makes
// atten(d_min) a sound upper bound over a cluster.
struct Attenuation {
  float constant = 0, linear = 0, quadratic = 1;
  float maxDistance = kInf;  // cutoff_distance: no light beyond it

  float operator()(float d) const {
    if (d > maxDistance) return 0.0f;
    float den = constant + d * (linear + d * quadratic);
    return den <= 1.0f ? 1.0f : 1.0f / den;
  }
  // d/dd of operator(): 0 where it is clamped to 1 or cut off.
  float derivative(float d) const {
    if (d > maxDistance) return 0.0f;
    float den = constant + d * (linear + d * quadratic);
    return den <= 1.0f ? 0.0f : -(linear + 2 * quadratic * d) / (den * den);
  }
  // Whether the clamp's corner (den = 1) lies between d0 <= d1: operator() is not smooth there.
  bool kinkBetween(float d0, float d1) const {
    float den0 = constant + d0 * (linear + d0 * quadratic);
    float den1 = constant + d1 * (linear + d1 * quadratic);
    return den0 <= 1.0f && den1 > 1.0f;
  }
  bool operator==(const Attenuation& o) const {
    return constant == o.constant && linear == o.linear && quadratic == o.quadratic &&
           maxDistance == o.maxDistance;
  }
};

// Spot falloff as a function of cos(angle to the axis); non-decreasing in cos, so
// falloff(cos_upper_bound) bounds a cluster. Course (seed) form: max(0,cos)^exponent, zero at or
// beyond the cutoff angle. UW form: smoothstep over [cone - penumbra, cone].
struct SpotFalloff {
  float exponent = 0;
  float cosCutoff = 0;     // cos(cutoff); zero at or beyond it (cutoff 90 deg: cos 0)
  float cosOuter = -2;     // smooth form: zero below cos(cone angle); -2 = unused
  float cosInner = -2;     // smooth form: full above cos(cone angle - penumbra)

  float operator()(float c) const {
    if (c <= cosCutoff) return 0.0f;
    float f = exponent == 0 ? 1.0f : powNonNegative(std::max(c, 0.0f), exponent);
    if (cosOuter > -2) {
      if (c <= cosOuter) return 0.0f;
      if (c < cosInner) {
        float t = (c - cosOuter) / (cosInner - cosOuter);
        f *= t * t * (3 - 2 * t);
      }
    }
    return f;
  }
  bool operator==(const SpotFalloff& o) const {
    return exponent == o.exponent && cosCutoff == o.cosCutoff && cosOuter == o.cosOuter &&
           cosInner == o.cosInner;
  }
};

struct LightGroup {
  Attenuation atten;
  SpotFalloff falloff;  // Spot lights only
  // Indirect lights (VPLs) light only the diffuse term of the receiver: their specular
  // lobes are the spiky artefact instant radiosity is known for.
  bool diffuseOnly = false;
  // VPLs whose attenuation clamps the 1/d^2 singularity: with atten = min(1, 1/(c d^2)),
  // the unclamped value is 1/(c d^2); kept for the clamped-energy statistic.
  bool isVpl = false;

  bool operator==(const LightGroup& o) const {
    return atten == o.atten && falloff == o.falloff && diffuseOnly == o.diffuseOnly &&
           isVpl == o.isVpl;
  }
};

// A group whose attenuation and falloff are at least those of both a and b at every
// distance and angle (each is non-increasing in its coefficients, cone cosines and
// exponent): what bounds a cluster that mixes the two. Both must agree on diffuseOnly and
// isVpl. Not a lower bound of either.
inline LightGroup upperEnvelope(const LightGroup& a, const LightGroup& b) {
  LightGroup e = a;
  e.atten.constant = std::min(a.atten.constant, b.atten.constant);
  e.atten.linear = std::min(a.atten.linear, b.atten.linear);
  e.atten.quadratic = std::min(a.atten.quadratic, b.atten.quadratic);
  e.atten.maxDistance = std::max(a.atten.maxDistance, b.atten.maxDistance);
  e.falloff.exponent = std::min(a.falloff.exponent, b.falloff.exponent);
  e.falloff.cosCutoff = std::min(a.falloff.cosCutoff, b.falloff.cosCutoff);
  // The smooth edge (cosOuter > -2) multiplies by a smoothstep that grows as either cosine
  // falls; a group without one multiplies by 1, so the envelope has none then.
  if (a.falloff.cosOuter <= -2 || b.falloff.cosOuter <= -2) {
    e.falloff.cosOuter = e.falloff.cosInner = -2;
  } else {
    e.falloff.cosOuter = std::min(a.falloff.cosOuter, b.falloff.cosOuter);
    e.falloff.cosInner = std::min(a.falloff.cosInner, b.falloff.cosInner);
  }
  return e;
}

// The other side: a group at most a's and b's at every distance and angle, what bounds a
// mixed cluster from below.
inline LightGroup lowerEnvelope(const LightGroup& a, const LightGroup& b) {
  LightGroup e = a;
  e.atten.constant = std::max(a.atten.constant, b.atten.constant);
  e.atten.linear = std::max(a.atten.linear, b.atten.linear);
  e.atten.quadratic = std::max(a.atten.quadratic, b.atten.quadratic);
  e.atten.maxDistance = std::min(a.atten.maxDistance, b.atten.maxDistance);
  e.falloff.exponent = std::max(a.falloff.exponent, b.falloff.exponent);
  e.falloff.cosCutoff = std::max(a.falloff.cosCutoff, b.falloff.cosCutoff);
  // A group without a smooth edge multiplies by 1, above any edge's smoothstep.
  if (a.falloff.cosOuter <= -2) {
    e.falloff.cosOuter = b.falloff.cosOuter;
    e.falloff.cosInner = b.falloff.cosInner;
  } else if (b.falloff.cosOuter > -2) {
    e.falloff.cosOuter = std::max(a.falloff.cosOuter, b.falloff.cosOuter);
    e.falloff.cosInner = std::max(a.falloff.cosInner, b.falloff.cosInner);
  }
  return e;
}

struct Light {
  Vec3 position;    // unused for directional lights
  Vec3 direction;   // oriented: unit surface normal; spot: unit axis; directional: unit travel direction
  Color intensity;  // RGB
  LightType type = LightType::Omni;
  uint16_t group = 0;  // index into LightSet::groups
};

// All lights of a scene plus the shared group table. Filled by the scene loader (point,
// spot, directional), object lights and VPL generation; read by every light evaluator.
struct LightSet {
  // On huge pages when large (core/huge_pages.h): cuts read representatives at random over
  // hundreds of megabytes at millions of lights.
  HugeVector<Light> lights;
  std::vector<LightGroup> groups;
  static constexpr size_t kMaxGroups = 65535;  // Light::group is 16 bits

  // The index of an equal group, added when new (in constant time: a scene may give each
  // of its 50,000 spots a cone of its own). Throws past kMaxGroups distinct groups; callers
  // that know a file position check hasRoomFor first.
  uint16_t groupFor(const LightGroup& g) {
    syncIndex();
    auto [it, added] = index_.try_emplace(keyOf(g), uint16_t(groups.size()));
    if (added) {
      if (groups.size() >= kMaxGroups) {
        index_.erase(it);
        throw std::length_error("more than 65535 distinct light groups (attenuations, spot cones)");
      }
      groups.push_back(g);
      indexed_ = groups.size();
    }
    return it->second;
  }
  // Whether groupFor(g) can return without throwing.
  bool hasRoomFor(const LightGroup& g) {
    syncIndex();
    return groups.size() < kMaxGroups || index_.count(keyOf(g)) != 0;
  }
  // The lights of each type, in one pass over the array (325 MB at 10M VPL paths).
  std::array<size_t, kLightTypeCount> countsByType() const {
    std::array<size_t, kLightTypeCount> n{};
    for (const Light& l : lights) ++n[size_t(l.type)];
    return n;
  }
  size_t countOf(LightType t) const { return countsByType()[size_t(t)]; }
  size_t size() const { return lights.size(); }

 private:
  // The group's fields as bytes (+0 for -0, so that equal floats give equal keys).
  static std::string keyOf(const LightGroup& g) {
    const float f[] = {g.atten.constant, g.atten.linear, g.atten.quadratic, g.atten.maxDistance,
                       g.falloff.exponent, g.falloff.cosCutoff, g.falloff.cosOuter, g.falloff.cosInner};
    std::string k(sizeof f + 2, '\0');
    for (size_t i = 0; i < std::size(f); ++i) {
      float v = f[i] == 0 ? 0.0f : f[i];
      std::memcpy(&k[i * sizeof(float)], &v, sizeof v);
    }
    k[sizeof f] = char(g.diffuseOnly);
    k[sizeof f + 1] = char(g.isVpl);
    return k;
  }
  // Groups may be appended directly (tests, loaders): index the ones not seen yet.
  void syncIndex() {
    if (indexed_ > groups.size()) {
      index_.clear();
      indexed_ = 0;
    }
    for (; indexed_ < groups.size(); ++indexed_) index_.try_emplace(keyOf(groups[indexed_]), uint16_t(indexed_));
  }
  std::unordered_map<std::string, uint16_t> index_;
  size_t indexed_ = 0;
};

}  // namespace lc
