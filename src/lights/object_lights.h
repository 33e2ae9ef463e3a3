// Object lights: every object whose material has a `luminosity` becomes many point lights
// on its surface (the seed's "object lights"). See docs/SCENE_FORMAT.md for the keyword.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/progress.h"
#include "scene/scene.h"

namespace lc::lights {

enum class ObjectLightKind {
  Oriented,  // emit max(cos, 0) about the outward surface normal (default; both sides of a square)
  Omni,      // the seed's omni lights
};
enum class Placement {
  Stratified,  // area-uniform low-discrepancy samples over each triangle (default)
  Course,      // the course project's (the seed's) pattern: centroid, then along centroid-vertex lines, then between
};

// Their names (core/enum_names.h: the first of a value its name, then aliases), read by the
// parse and name functions and by --object-lights and --object-light-placement.
inline constexpr EnumName<ObjectLightKind> kObjectLightKindNames[] = {
    {ObjectLightKind::Oriented, "oriented", "cosine emission about the surface normal"},
    {ObjectLightKind::Omni, "omni", "the seed's"}};
inline constexpr EnumName<Placement> kPlacementNames[] = {
    {Placement::Stratified, "stratified", "area-uniform low-discrepancy"},
    {Placement::Course, "seed", "the seed's pattern"},
    {Placement::Course, "course"}};
inline const char* objectLightKindName(ObjectLightKind k) { return enumName(kObjectLightKindNames, k); }
inline const char* placementName(Placement p) { return enumName(kPlacementNames, p); }
// Throw lc::Error for another name.
inline ObjectLightKind parseObjectLightKind(std::string_view s) {
  return parseEnum(kObjectLightKindNames, s, "object light kind");
}
inline Placement parsePlacement(std::string_view s) { return parseEnum(kPlacementNames, s, "object light placement"); }

struct ObjectLightOptions {
  ObjectLightKind kind = ObjectLightKind::Oriented;
  Placement placement = Placement::Stratified;
  uint64_t maxLights = 20'000'000;  // --max-lights
  uint64_t seed = 1;  // --seed: shifts the stratified points (1: none); the seed pattern ignores it
  ProgressFn progress = {};  // called with the share of lights placed (core/progress.h)
  // When set and it becomes true, placement stops within a block of lights and
  // addObjectLights throws lc::Interrupted.
  const std::atomic<bool>* cancel = nullptr;
};

// What was generated for one luminous object (for `lightcuts info` and --stats).
struct ObjectLightInfo {
  int shape = -1;
  std::string name;
  uint64_t lights = 0;
  double area = 0;   // world-space surface area
  Color power;       // total emitted intensity (sum of the lights' intensities)
};

// Appends the lights of every luminous object to scene.lights(). Throws lc::Error (with the
// luminosity's file:line:column) for bad values or when --max-lights would be exceeded,
// before allocating anything.
std::vector<ObjectLightInfo> addObjectLights(scene::Scene& scene, const ObjectLightOptions& options);

}  // namespace lc::lights
