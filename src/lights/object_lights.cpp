// Placeholder until object lights land.
#include "lights/object_lights.h"

#include "core/error.h"

namespace lc::lights {

ObjectLightKind parseObjectLightKind(const std::string& s) {
  if (s == "oriented") return ObjectLightKind::Oriented;
  if (s == "omni") return ObjectLightKind::Omni;
  throw Error("unknown object light kind '" + s + "' (use oriented or omni)");
}

Placement parsePlacement(const std::string& s) {
  if (s == "stratified") return Placement::Stratified;
  if (s == "seed") return Placement::Seed;
  throw Error("unknown object light placement '" + s + "' (use stratified or seed)");
}

std::vector<ObjectLightInfo> addObjectLights(scene::Scene& scene, const ObjectLightOptions&) {
  for (const auto& m : scene.materials())
    if (m.luminosity) throw Error(m.luminosity->loc, "object lights (luminosity) are not supported yet");
  return {};
}

}  // namespace lc::lights
