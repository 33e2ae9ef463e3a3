#include "app/summary.h"

#include <fmt/format.h>

namespace lc::app {

nlohmann::json lightCountsJson(const LightSet& ls) {
  nlohmann::json j;
  for (int t = 0; t < kLightTypeCount; ++t) j[lightTypeName(LightType(t))] = ls.countOf(LightType(t));
  j["total"] = ls.size();
  return j;
}

std::string lightCountsLine(const LightSet& ls) {
  std::string kinds;
  for (int t = 0; t < kLightTypeCount; ++t)
    if (size_t c = ls.countOf(LightType(t)))
      kinds += fmt::format("{}{} {}", kinds.empty() ? "" : ", ", c, lightTypeName(LightType(t)));
  return fmt::format("{}{}", ls.size(), kinds.empty() ? "" : " (" + kinds + ")");
}

nlohmann::json objectLightsJson(const std::vector<lights::ObjectLightInfo>& infos) {
  nlohmann::json objs = nlohmann::json::array();
  for (const auto& o : infos)
    objs.push_back({{"shape", o.shape}, {"name", o.name}, {"lights", o.lights}, {"area", o.area},
                    {"power", {o.power.x, o.power.y, o.power.z}}});
  return objs;
}

nlohmann::json environmentLightsJson(const std::vector<lights::EnvironmentLightInfo>& infos) {
  nlohmann::json envs = nlohmann::json::array();
  for (const auto& e : infos)
    envs.push_back({{"what", e.what}, {"lights", e.lights}, {"power", {e.power.x, e.power.y, e.power.z}}});
  return envs;
}

}  // namespace lc::app
