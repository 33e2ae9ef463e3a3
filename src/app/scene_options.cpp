#include "app/scene_options.h"

#include <cmath>
#include <sstream>

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

void addSceneOptions(CLI::App& c, LoadOptions& o) {
  c.add_flag("--lenient", o.lenient, "Skip unknown keywords in .ray files with a warning instead of failing");
  c.add_option("--object-lights", [&o](const CLI::results_t& r) {
     o.objectLights.kind = lights::parseObjectLightKind(r[0]);
     return true;
   }, "Lights of luminous objects: oriented (cosine emission about the surface normal, default) or omni (the seed's)")
      ->check(CLI::IsMember({"oriented", "omni"}));
  c.add_option("--object-light-placement", [&o](const CLI::results_t& r) {
     o.objectLights.placement = lights::parsePlacement(r[0]);
     return true;
   }, "Where object lights go: stratified (area-uniform low-discrepancy, default) or seed (the seed's pattern)")
      ->check(CLI::IsMember({"stratified", "seed"}));
  c.add_option_function<float>("--emission-density", [&o](const float& v) { o.emissionDensity = v; },
                               "Point lights per unit of world area for `emission = (r,g,b)` object lights (default 1)")
      ->check(CLI::Range(0.0f, 1e30f));
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
   }, "Attenuation A,B,C (constant, linear, quadratic; each >= 0) of point and spot lights that set none "
      "(the UW renderer's sliders)")
      ->type_name("A,B,C");
  c.add_option_function<int>("--vpls", [&o](const int& v) { o.vplCount = v; },
                             "Instant radiosity: number of light paths shot for virtual point lights (overrides the scene)")
      ->check(CLI::Range(0, 1 << 30));
  c.add_option_function<int>("--bounces", [&o](const int& v) { o.bounces = v; }, "Instant radiosity: diffuse bounces (default 1)")
      ->check(CLI::Range(0, 64));
  c.add_option_function<std::string>("--vpl-normalize", [&o](const std::string& v) { o.vplNormalize = v; },
                                     "VPL intensities: power (energy conserving, default) or object (the seed's per-object division)")
      ->check(CLI::IsMember({"power", "object"}));
  c.add_option_function<float>("--vpl-clamp", [&o](const float& v) { o.vplClamp = v; },
                               "VPL distance clamp, as a fraction of half the scene diagonal (default 0.05)")
      ->check(CLI::Range(0.0f, 1e6f));
  c.add_option_function<std::string>("--gi", [&o](const std::string& v) { o.gi = v == "on"; },
                                     "Global illumination from VPLs: on (default) or off")
      ->check(CLI::IsMember({"on", "off"}));
  c.add_option("--max-lights", o.limits.maxLights, "Limit on lights (object lights, VPLs and scene lights)")
      ->check(kLimitValue);
  c.add_option("--max-vpls", o.limits.maxVpls, "Limit on VPLs")
      ->check(kLimitValue);
  c.add_option_function<uint64_t>("--max-triangles", [&o](const uint64_t& v) { o.limits.maxTriangles = o.limits.maxVertices = v; },
                                  "Limit on triangles (and vertices) in all meshes")
      ->check(kLimitValue);
  c.add_option("--max-nesting", o.limits.maxNesting, "Limit on nested transforms and groups in .ray files")
      ->check(kLimitValue);
  c.add_option("--max-objects", o.limits.maxObjects, "Limit on primitives and materials in a .ray file")
      ->check(kLimitValue);
  c.add_option("--max-image-pixels", o.limits.maxImagePixels, "Limit on width x height")
      ->check(kLimitValue);
  c.add_option("--max-texture-pixels", o.limits.maxTexturePixels, "Limit on the pixels of one texture")
      ->check(kLimitValue);
}

}  // namespace lc::app
