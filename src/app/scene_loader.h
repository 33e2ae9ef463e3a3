// Loading a scene for the CLI: parse (.ray or .obj), build geometry and materials, then
// add the generated lights (object lights, VPLs), timing each phase.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/limits.h"
#include "lights/environment_lights.h"
#include "lights/caustics.h"
#include "lights/object_lights.h"
#include "lights/vpl.h"
#include "scene/scene.h"

namespace lc::app {

struct LoadOptions {
  bool lenient = false;
  Limits limits;
  int threads = 0;
  // io::ParseOptions: --emission-density and --default-attenuation (.ray files).
  float emissionDensity = 1;
  std::optional<std::array<float, 3>> defaultAttenuation;
  lights::ObjectLightOptions objectLights;
  // Instant radiosity: command-line values override the scene's instant_radiosity block.
  std::optional<int> vplCount, bounces;
  std::optional<io::VplNormalize> vplNormalize;
  std::optional<float> vplClamp;
  // render --seed: overrides the scene's instant_radiosity seed when given; unset, the scene's
  // seed or VplOptions' default stands.
  std::optional<uint64_t> vplSeed;
  // --env-lights N: directional lights per environment_light / sun_sky_light (overrides
  // their `lights`); the point set's seed (render --seed).
  std::optional<int> envLights;
  uint64_t envSeed = 1;
  bool gi = true;             // --gi off ignores instant_radiosity's VPLs and --vpls (not caustics)
  // Caustics (lights/caustics.h): --caustics and --caustic-lights over instant_radiosity's
  // caustics and caustic_lights.
  std::optional<int> causticPaths;
  std::optional<io::CausticLightKind> causticLights;
  std::optional<float> causticSmoothing;
  // Linearise sRGB-marked (MTL) textures: scene::BuildOptions::linearizeSrgbTextures.
  bool linearizeSrgbTextures = false;
  // scene::BuildOptions::occluders: for lightcuts with --clear-clusters on.
  bool occluders = true;
  // scene::BuildOptions::planarFaces: for lightcuts with --visibility-probes on.
  bool planarFaces = true;
  bool quiet = false;
  // SIGINT/SIGTERM stop the object lights and VPLs (app/interrupt.h): loadScene then throws
  // lc::Interrupted. Off, the signals keep their default effect.
  bool interruptible = false;
};

struct LoadedScene {
  std::unique_ptr<scene::Scene> scene;
  std::vector<lights::ObjectLightInfo> objectLights;
  std::vector<lights::EnvironmentLightInfo> environmentLights;
  lights::VplInfo vpls;
  lights::CausticInfo caustics;
  std::vector<std::string> warnings;
  std::string objDescription;  // the default camera/lights added for an OBJ file, in .ray syntax
  double loadSeconds = 0;      // parsing and textures
  double accelSeconds = 0;     // Embree BVH (and the occluder index, when built)
  double lightSeconds = 0;     // object lights, environment lights and VPLs
};

LoadedScene loadScene(const std::string& path, const LoadOptions& options);

}  // namespace lc::app
