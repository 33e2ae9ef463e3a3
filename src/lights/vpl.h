// Instant radiosity (Keller 1997): virtual point lights (VPLs) shot from the scene's lights.
// Each diffuse hit of a light path leaves an oriented light facing along the surface normal
// whose colour is the carried power times the surface's diffuse colour.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "core/progress.h"
#include "core/rng.h"
#include "io/scene_desc.h"
#include "scene/scene.h"

namespace lc::lights {

// The values, their names and their parsing: io/scene_desc.h (the scene's
// instant_radiosity block and --vpl-normalize share them).
using io::VplNormalize;

struct VplOptions {
  int count = 0;       // --vpls: paths shot (VPLs deposited can differ with bounces)
  int bounces = 1;     // --bounces
  VplNormalize normalize = VplNormalize::Power;
  float clamp = 0.05f; // --vpl-clamp: minimum distance, as a fraction of half the scene diagonal
  uint64_t seed = 1;
  uint64_t maxVpls = 10'000'000;
  ProgressFn progress = {};  // called with the share of paths shot (core/progress.h)
  // When set and it becomes true, shooting stops within a block of paths and addVpls throws
  // lc::Interrupted (the scene's lights are left as they were).
  const std::atomic<bool>* cancel = nullptr;
};

struct VplInfo {
  uint64_t paths = 0;
  uint64_t vpls = 0;
  double seconds = 0;
  float clampDistance = 0;  // world units
  Color power;              // total intensity carried by the VPLs
};

// Light paths from a scene's lights: a light picked in proportion to its emitted power, a
// direction from its emission (omni: the sphere; oriented: cosine; spot: the cone, weighted
// by the falloff; directional: a disk covering the scene). Shared by the VPLs and the
// caustics (lights/caustics.h).
class EmissionSampler {
 public:
  EmissionSampler(const scene::Scene& scene, const LightSet& set, std::vector<Light> sources);
  bool hasPower() const { return total_ > 0 && !sources_.empty(); }

  struct Sample {
    Vec3 origin, dir;
    Color flux;  // the light's intensity * G(w) / (p(w) * P_light * n): what one of n paths carries
    const Light* light = nullptr;
    const LightGroup* group = nullptr;
    // The factor for the first hit at distance t: atten(t) t^2 (1 for directional lights).
    float firstHit(float t) const;
  };
  // One path of n, drawn with rng (its first draw picks the light). Needs hasPower().
  Sample sample(Rng& rng, size_t n) const;

 private:
  const LightSet& set_;
  std::vector<Light> sources_;
  std::vector<double> cdf_;
  double total_ = 0;
  float radius_ = 1, eps_ = 1e-4f;
  Vec3 centre_;
};

// Appends VPLs to scene.lights(). Throws lc::Error for bad options or limits.
VplInfo addVpls(scene::Scene& scene, const VplOptions& options);

}  // namespace lc::lights
