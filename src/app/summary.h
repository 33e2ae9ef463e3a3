// What the commands report, apart from the work: a loaded scene's lights (shared by
// `render` and `info`) as JSON for --stats/--json and as one line for the terminal, and
// `render`'s own report, its terminal summary and its --stats JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/render_args.h"
#include "app/scene_loader.h"
#include "lightcuts/light_tree.h"
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

// One rank's part of a distributed render: rank 0 puts every rank's under "mpi" in --stats
// and adds their counters ("counters", removed there) to the job's totals.
nlohmann::json rankStatsJson(int rank, const std::string& host, int threads, const LoadedScene& ls,
                             double treeSeconds, const render::RenderResult& rr);

// What `render` reports: the command line (sizes resolved), the scene, the method and its
// tree, the render's options and result.
struct RenderReport {
  const RenderArgs& args;
  const LoadedScene& loaded;
  lightcuts::Method method;
  lightcuts::TreeBuilder treeBuilder;
  float error;  // --error, resolved by method
  const lightcuts::LightForest& forest;
  const render::RenderOptions& options;
  const render::RenderResult& result;
  double clampedFraction = 0;  // render::vplClampedFraction
  double totalSeconds = 0;     // from the command's start to the report
  // A distributed render: its ranks, how evenly they finished (mean over max of their tile
  // times) and each rank's rankStatsJson (without counters); null when one process renders.
  int ranks = 1;
  double loadBalance = 1;
  const nlohmann::json* perRank = nullptr;
};
// The --stats JSON.
nlohmann::json renderStatsJson(const RenderReport& report);
// The summary on stdout (scene, lights, method, image, times, rays, error).
void printRenderSummary(const RenderReport& report);

}  // namespace lc::app
