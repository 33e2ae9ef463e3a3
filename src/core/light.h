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
#include <cstdint>
#include <string>
#include <vector>

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
  std::vector<Light> lights;
  std::vector<LightGroup> groups;

  // The index of an equal group, added when new.
  uint16_t groupFor(const LightGroup& g) {
    for (size_t i = 0; i < groups.size(); ++i)
      if (groups[i] == g) return uint16_t(i);
    groups.push_back(g);
    return uint16_t(groups.size() - 1);
  }
  size_t countOf(LightType t) const {
    size_t n = 0;
    for (const Light& l : lights) n += l.type == t;
    return n;
  }
  size_t size() const { return lights.size(); }
};

}  // namespace lc
