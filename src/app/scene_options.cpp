#include "app/scene_options.h"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "core/memory_budget.h"
#include "io/scene_desc.h"

namespace lc::app {

namespace {

// Limits take non-negative integers only: a negative one used to wrap around to a huge
// unsigned value (silently no limit) or to read "a limit of -1". 0 allows none.
const CLI::Validator kLimitValue(
    [](std::string& s) -> std::string {
      size_t i = 0;
      while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
      if (s.empty() || i != s.size()) return "a limit must be a whole number >= 0 (0 allows none), got " + s;
      return {};
    },
    "INT>=0");

}  // namespace

const char* switchName(bool on) { return on ? "on" : "off"; }

CLI::Option* addSwitch(CLI::App& c, const std::string& name, bool& value, const std::string& help) {
  return c.add_option_function<std::string>(name, [&value](const std::string& v) { value = v == "on"; }, help)
      ->check(CLI::IsMember({"on", "off"}));
}

void addSceneOptions(CLI::App& c, LoadOptions& o) {
  // Defaults as the loader sees them: o's own values, and VplOptions' and LightDesc's for
  // what o leaves unset (the scene's instant_radiosity block comes between).
  const lights::VplOptions vpl;
  const io::LightDesc light;
  const std::string lightsGroup = "Lights & GI";
  const std::string limitsGroup = "Limits";

  c.add_flag("--lenient", o.lenient,
             fmt::format("Skip unknown keywords in .ray files with a warning instead of failing (default {})",
                         o.lenient ? "on" : "off"))
      ->group("Scene");
  // Options with named values: their names, checked here once, and the help's list come
  // from their enums' tables (lights/object_lights.h, io/scene_desc.h).
  addEnumOption(c, "--object-lights", lights::kObjectLightKindNames,
                [&o](lights::ObjectLightKind k) { o.objectLights.kind = k; },
                fmt::format("Lights of luminous objects: {}; default {}", enumHelp(lights::kObjectLightKindNames),
                            lights::objectLightKindName(o.objectLights.kind)))
      ->group(lightsGroup);
  addEnumOption(c, "--object-light-placement", lights::kPlacementNames,
                [&o](lights::Placement p) { o.objectLights.placement = p; },
                fmt::format("Where object lights go: {}; default {}", enumHelp(lights::kPlacementNames),
                            lights::placementName(o.objectLights.placement)))
      ->group(lightsGroup);
  c.add_option_function<float>("--emission-density", [&o](const float& v) { o.emissionDensity = v; },
                               fmt::format("Point lights per unit of world area for `emission = (r,g,b)` object "
                                           "lights; default {}", o.emissionDensity))
      ->check(CLI::Range(0.0f, 1e30f))
      ->group(lightsGroup);
  c.add_option("--default-attenuation", [&o](const CLI::results_t& r) {
     std::array<float, 3> a{};
     std::string s = r[0];
     for (char& ch : s)
       if (ch == ',') ch = ' ';
     std::istringstream in(s);
     std::string extra;
     for (float& v : a)
       if (!(in >> v) || !std::isfinite(v) || v < 0) return false;
     if (in >> extra) return false;
     o.defaultAttenuation = a;
     return true;
   }, fmt::format("Attenuation A,B,C (constant, linear, quadratic; each >= 0) of point and spot lights that set "
                  "none (the UW renderer's sliders); default {},{},{}",
                  light.attenConstant, light.attenLinear, light.attenQuadratic))
      ->type_name("A,B,C")
      ->group(lightsGroup);
  c.add_option_function<int>("--vpls", [&o](const int& v) { o.vplCount = v; },
                             fmt::format("Instant radiosity: number of light paths shot for virtual point lights "
                                         "(overrides the scene); default the scene's instant_radiosity vpls, else {}",
                                         vpl.count))
      ->check(CLI::Range(0, 1 << 30))
      ->group(lightsGroup);
  c.add_option_function<int>("--bounces", [&o](const int& v) { o.bounces = v; },
                             fmt::format("Instant radiosity: diffuse bounces; default the scene's, else {}", vpl.bounces))
      ->check(CLI::Range(0, 64))
      ->group(lightsGroup);
  addEnumOption(c, "--vpl-normalize", io::kVplNormalizeNames, [&o](io::VplNormalize v) { o.vplNormalize = v; },
                fmt::format("VPL intensities: {}; default the scene's, else {}", enumHelp(io::kVplNormalizeNames),
                            io::vplNormalizeName(vpl.normalize)))
      ->group(lightsGroup);
  c.add_option_function<float>("--vpl-clamp", [&o](const float& v) { o.vplClamp = v; },
                               fmt::format("VPL distance clamp, as a fraction of half the scene diagonal; default the "
                                           "scene's, else {}", vpl.clamp))
      ->check(CLI::Range(0.0f, 1e6f))
      ->group(lightsGroup);
  c.add_option_function<int>("--env-lights", [&o](const int& v) { o.envLights = v; },
                             "Directional lights each environment_light / sun_sky_light becomes (overrides their "
                             "`lights`); default the scene's, else 4096")
      ->check(CLI::Range(1, 1 << 30))
      ->group(lightsGroup);
  c.add_option_function<int>("--caustics", [&o](const int& v) { o.causticPaths = v; },
                             "Caustics: light paths shot through mirrors and glass; each that reaches a diffuse surface "
                             "leaves a caustic light, and shadow rays stop at glass (docs/LIGHTCUTS.md); default the "
                             "scene's instant_radiosity caustics, else 0 (off)")
      ->check(CLI::Range(0, 1 << 30))
      ->group(lightsGroup);
  addEnumOption(c, "--caustic-lights", io::kCausticLightKindNames, [&o](io::CausticLightKind k) { o.causticLights = k; },
                fmt::format("Caustic lights: {}; default the scene's, else {}", enumHelp(io::kCausticLightKindNames),
                            io::causticLightKindName(lights::CausticOptions{}.kind)))
      ->group(lightsGroup);
  c.add_option_function<float>("--caustic-smoothing", [&o](const float& v) { o.causticSmoothing = v; },
                               fmt::format("Caustic lights' footprint, times the distance to the {}th nearest other "
                                           "caustic hit; default {}", lights::CausticOptions{}.neighbours,
                                           lights::CausticOptions{}.smoothing))
      ->check(CLI::Range(1e-3f, 1e3f))
      ->group(lightsGroup);
  addSwitch(c, "--gi", o.gi, fmt::format("Global illumination from VPLs: on or off; default {}", switchName(o.gi)))
      ->group(lightsGroup);
  c.add_option("--max-lights", o.limits.maxLights,
               fmt::format("Limit on lights (object lights, VPLs and scene lights); default {}", o.limits.maxLights))
      ->check(kLimitValue)
      ->group(limitsGroup);
  c.add_option("--max-vpls", o.limits.maxVpls, fmt::format("Limit on VPLs; default {}", o.limits.maxVpls))
      ->check(kLimitValue)
      ->group(limitsGroup);
  c.add_option_function<uint64_t>("--max-triangles", [&o](const uint64_t& v) { o.limits.maxTriangles = o.limits.maxVertices = v; },
                                  fmt::format("Limit on triangles (and vertices) in all meshes; default {}",
                                              o.limits.maxTriangles))
      ->check(kLimitValue)
      ->group(limitsGroup);
  c.add_option("--max-nesting", o.limits.maxNesting,
               fmt::format("Limit on nested transforms and groups in .ray files; default {}", o.limits.maxNesting))
      ->check(kLimitValue)
      ->group(limitsGroup);
  c.add_option("--max-objects", o.limits.maxObjects,
               fmt::format("Limit on primitives and materials in a .ray file; default {}", o.limits.maxObjects))
      ->check(kLimitValue)
      ->group(limitsGroup);
  c.add_option("--max-image-pixels", o.limits.maxImagePixels,
               fmt::format("Limit on width x height; default {}", o.limits.maxImagePixels))
      ->check(kLimitValue)
      ->group(limitsGroup);
  // One process-wide budget (core/memory_budget.h): set here, counted by the loaders.
  c.add_option_function<std::string>(
       "--max-memory", [](const std::string& v) { processBudget().setLimit(*parseBytes(v)); },
       fmt::format("Budget on the memory that the scene, its textures, lights and the image need, counted before "
                   "they are allocated: bytes, or with a K/M/G/T suffix (8G); default 80% of physical memory "
                   "({})",
                   formatBytes(MemoryBudget::defaultLimit())))
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            return parseBytes(s) ? std::string() : "a memory size must be bytes >= 0, or with K/M/G/T (8G), got " + s;
          },
          "SIZE"))
      ->group(limitsGroup);
  c.add_option("--max-texture-pixels", o.limits.maxTexturePixels,
               fmt::format("Limit on the pixels of one texture; default {}", o.limits.maxTexturePixels))
      ->check(kLimitValue)
      ->group(limitsGroup);
}

}  // namespace lc::app
