// Instant radiosity (Keller 1997): virtual point lights (VPLs) shot from the scene's lights.
// Each diffuse hit of a light path leaves an oriented light facing along the surface normal
// whose colour is the carried power times the surface's diffuse colour.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "core/progress.h"
#include "scene/scene.h"

namespace lc::lights {

enum class VplNormalize {
  Power,   // energy conserving: each path carries its light's power / number of paths (default)
  Object,  // the seed's: a VPL's intensity divided by the number of VPLs on its object
};
VplNormalize parseVplNormalize(const std::string& s);

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

// Appends VPLs to scene.lights(). Throws lc::Error for bad options or limits.
VplInfo addVpls(scene::Scene& scene, const VplOptions& options);

}  // namespace lc::lights
