// Descriptions of a loaded scene's lights shared by `render` and `info`: as JSON for
// --stats/--json and as one line for the terminal.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lights/environment_lights.h"
#include "lights/object_lights.h"
#include "core/light.h"
#include "render/renderer.h"

namespace lc::app {

// {"omni": n, "oriented": n, "spot": n, "directional": n, "total": n}
nlohmann::json lightCountsJson(const LightSet& lights);
// "9166 (256 oriented, ...)": the total, then the non-zero kinds.
std::string lightCountsLine(const LightSet& lights);
// One object per luminous object: shape, name, lights, area, power.
nlohmann::json objectLightsJson(const std::vector<lights::ObjectLightInfo>& infos);

// One object per environment_light / sun_sky_light: what it is, its directional lights
// and their power (sum of intensities x pi).
nlohmann::json environmentLightsJson(const std::vector<lights::EnvironmentLightInfo>& infos);
// A render's counters (rays, cuts, reconstruction) as JSON and back, to add the ranks'
// statistics of a distributed render on rank 0: addRenderCounters(s, renderCountersJson(t))
// adds t's counters to s (times are left alone).
nlohmann::json renderCountersJson(const render::RenderStats& stats);
void addRenderCounters(render::RenderStats& stats, const nlohmann::json& counters);

}  // namespace lc::app
