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

namespace {
// Every counter of EvalStats, in one order for both directions.
template <class S, class F>
void forEachEvalCounter(S& s, F&& f) {
  f("shading_points", s.shadingPoints);
  f("cut_nodes", s.cutNodes);
  f("shadow_rays", s.shadowRays);
  f("bounds_evaluated", s.boundsEvaluated);
  f("reconstructed_points", s.reconstructedPoints);
  f("probed_clusters", s.probedClusters);
  f("probe_rays", s.probeRays);
  f("occluded_rays", s.occludedRays);
  f("hidden_clusters", s.hiddenClusters);
  f("group_probes", s.groupProbes);
  f("failed_group_probes", s.failedGroupProbes);
  f("traced_rays", s.tracedRays);
  f("timed_rays", s.timedRays);
  f("timed_ray_nanos", s.timedRayNanos);
  f("lit_points", s.litPoints);
  f("timed_points", s.timedPoints);
  f("lighting_nanos", s.lightingNanos);
}
}  // namespace

nlohmann::json renderCountersJson(const render::RenderStats& st) {
  nlohmann::json j;
  forEachEvalCounter(st.eval, [&](const char* k, uint64_t v) { j[k] = v; });
  j["cut_histogram"] = st.eval.cutHistogram;
  j["primary_rays"] = st.primaryRays;
  j["secondary_rays"] = st.secondaryRays;
  j["reconstruction_samples"] = st.reconstructionSamples;
  j["reconstruction_fallbacks"] = st.reconstructionFallbacks;
  j["reconstruction_coarse_cells"] = st.reconstructionCoarseCells;
  j["aa_pixels"] = st.aaPixels;
  j["aa_sub_samples"] = st.aaSubSamples;
  return j;
}

void addRenderCounters(render::RenderStats& st, const nlohmann::json& j) {
  lightcuts::EvalStats e;
  forEachEvalCounter(e, [&](const char* k, uint64_t& v) { v = j.at(k).get<uint64_t>(); });
  e.cutHistogram = j.at("cut_histogram").get<decltype(e.cutHistogram)>();
  st.eval.add(e);
  st.primaryRays += j.at("primary_rays").get<uint64_t>();
  st.secondaryRays += j.at("secondary_rays").get<uint64_t>();
  st.reconstructionSamples += j.at("reconstruction_samples").get<uint64_t>();
  st.reconstructionFallbacks += j.at("reconstruction_fallbacks").get<uint64_t>();
  st.reconstructionCoarseCells += j.at("reconstruction_coarse_cells").get<uint64_t>();
  st.aaPixels += j.at("aa_pixels").get<uint64_t>();
  st.aaSubSamples += j.at("aa_sub_samples").get<uint64_t>();
}

}  // namespace lc::app
