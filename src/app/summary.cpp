#include "app/summary.h"

#include <fmt/format.h>

#include <thread>

#include "app/progress.h"
#include "app/scene_options.h"

namespace lc::app {

nlohmann::json lightCountsJson(const LightSet& ls) {
  nlohmann::json j;
  const auto counts = ls.countsByType();
  for (int t = 0; t < kLightTypeCount; ++t) j[lightTypeName(LightType(t))] = counts[size_t(t)];
  j["total"] = ls.size();
  return j;
}

std::string lightCountsLine(const LightSet& ls) {
  std::string kinds;
  const auto counts = ls.countsByType();
  for (int t = 0; t < kLightTypeCount; ++t)
    if (size_t c = counts[size_t(t)])
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
  f("reconstructed_shadow_rays", s.reconstructedRays);
  f("probed_clusters", s.probedClusters);
  f("probes_ruled_out", s.probesRuledOut);
  f("probe_rays", s.probeRays);
  f("second_sample_rays", s.secondSamples);
  f("second_samples_hidden", s.secondSamplesHidden);
  f("occluded_rays", s.occludedRays);
  f("hidden_clusters", s.hiddenClusters);
  f("clear_tests", s.clearTests);
  f("cleared_clusters", s.clearedClusters);
  f("cuts_at_max_cut", s.cutsAtMaxCut);
  f("group_probes", s.groupProbes);
  f("failed_group_probes", s.failedGroupProbes);
  f("refuting_group_probes", s.refutingGroupProbes);
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
  j["reconstruction_split_cells"] = st.reconstructionSplitCells;
  j["reconstruction_refined_cells"] = st.reconstructionRefinedCells;
  j["aa_pixels"] = st.aaPixels;
  j["aa_seam_pixels"] = st.aaSeamPixels;
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
  st.reconstructionSplitCells += j.at("reconstruction_split_cells").get<uint64_t>();
  st.reconstructionRefinedCells += j.at("reconstruction_refined_cells").get<uint64_t>();
  st.aaPixels += j.at("aa_pixels").get<uint64_t>();
  st.aaSeamPixels += j.at("aa_seam_pixels").get<uint64_t>();
  st.aaSubSamples += j.at("aa_sub_samples").get<uint64_t>();
}

namespace {
// Lights and shadow rays per shading point, and every ray traced, as both the summary and
// --stats give them.
struct Rates {
  double perPoint, raysPerPoint;
  uint64_t allRays;
};
Rates rates(const render::RenderStats& st) {
  const auto& es = st.eval;
  return {es.shadingPoints ? double(es.cutNodes) / double(es.shadingPoints) : 0,
          es.shadingPoints ? double(es.shadowRays) / double(es.shadingPoints) : 0,
          st.primaryRays + st.secondaryRays + es.shadowRays};
}
}  // namespace

nlohmann::json rankStatsJson(int rank, const std::string& host, int threads, const LoadedScene& ls,
                             double treeSeconds, const render::RenderResult& rr) {
  const auto& st = rr.stats;
  uint64_t rays = st.primaryRays + st.secondaryRays + st.eval.shadowRays;
  return {{"rank", rank},
          {"host", host},
          {"threads", threads},
          {"tiles", st.tiles},
          {"pixels", st.pixels},
          {"time_load_s", ls.loadSeconds},
          {"time_accel_s", ls.accelSeconds},
          {"time_lights_s", ls.lightSeconds},
          {"time_tree_s", treeSeconds},
          {"time_tiles_s", st.tileSeconds},
          {"time_render_s", st.seconds},
          {"time_reference_s", st.reference.bruteSeconds},
          {"reference_pixels", st.reference.localPixels},
          {"primary_rays", st.primaryRays},
          {"secondary_rays", st.secondaryRays},
          {"shadow_rays", st.eval.shadowRays},
          {"shading_points", st.eval.shadingPoints},
          {"rays_per_second", st.tileSeconds > 0 ? double(rays) / st.tileSeconds : 0},
          {"counters", renderCountersJson(st)}};
}

nlohmann::json renderStatsJson(const RenderReport& r) {
  const RenderArgs& a = r.args;
  const LoadedScene& ls = r.loaded;
  const scene::Scene& scene = *ls.scene;
  const lightcuts::LightForest& forest = r.forest;
  const lightcuts::Method method = r.method;
  const render::RenderOptions& ro = r.options;
  const render::RenderResult& rr = r.result;
  const auto& es = rr.stats.eval;
  const auto [perPoint, raysPerPoint, allRays] = rates(rr.stats);
  const render::ReferenceStats& ref = rr.stats.reference;
  const float error = r.error;
  const double clampedFraction = r.clampedFraction, total = r.totalSeconds;
  nlohmann::json j;
  j["scene"] = a.scene;
  j["output"] = a.out;
  j["width"] = a.width;
  j["height"] = a.height;
  j["spp"] = a.spp;
  j["aa"] = render::antiAliasingName(a.spp == 1 ? a.aa : render::AntiAliasing::Off);
  j["aa_extrapolation_probe"] = a.aaExtrapolationProbe;
  j["aa_pixel_samples"] = a.aaPixelSamples;
  j["aa_samples"] = a.aaSamples;
  j["aa_pixels"] = rr.stats.aaPixels;
  j["aa_seam_pixels"] = rr.stats.aaSeamPixels;  // of aa_pixels, flagged across tile borders
  j["aa_sub_samples"] = rr.stats.aaSubSamples;
  j["threads"] = a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency());
  j["method"] = lightcuts::methodName(method);
  j["error_threshold"] = error;
  j["max_cut"] = a.maxCut;
  j["error_floor"] = rr.stats.errorFloor;
  j["error_floor_pixels"] = rr.stats.errorFloorPixels;
  j["cut_criterion"] = lightcuts::cutCriterionName(a.criterion);
  j["estimator"] = lightcuts::estimatorName(a.estimator);
  j["visibility_probes"] = switchName(a.visibilityProbes);
  j["probed_clusters"] = es.probedClusters;
  j["probes_ruled_out"] = es.probesRuledOut;
  j["probe_rays"] = es.probeRays;
  j["second_samples"] = switchName(a.secondSamples);
  j["second_sample_rays"] = es.secondSamples;
  j["second_samples_hidden"] = es.secondSamplesHidden;
  j["occluded_shadow_rays"] = es.occludedRays;
  j["hidden_clusters"] = es.hiddenClusters;
  j["clear_clusters"] = switchName(a.clearClusters);
  // What the floor's pre-pass found of the tests, and whether the render kept them
  // (lightcuts::clearTestsPay: off where under one in 16 passed).
  j["pre_pass_clear_tests"] = rr.stats.prePass.clearTests;
  j["pre_pass_cleared_clusters"] = rr.stats.prePass.clearedClusters;
  j["clear_tests_kept"] = switchName(a.clearClusters && rr.stats.clearTests);
  j["clear_tests"] = es.clearTests;
  j["cleared_clusters"] = es.clearedClusters;
  j["cuts_at_max_cut"] = es.cutsAtMaxCut;
  j["group_probes"] = es.groupProbes;
  j["failed_group_probes"] = es.failedGroupProbes;
  j["refuting_group_probes"] = es.refutingGroupProbes;
  j["reconstruct_spacing"] = ro.reconstructSpacing;
  j["reconstruct_coarse_spacing"] = ro.reconstructCoarseSpacing;
  j["reconstruction_samples"] = rr.stats.reconstructionSamples;
  j["reconstructed_points"] = es.reconstructedPoints;
  j["reconstructed_shadow_rays"] = es.reconstructedRays;
  j["reconstruction_fallbacks"] = rr.stats.reconstructionFallbacks;
  j["reconstruction_coarse_cells"] = rr.stats.reconstructionCoarseCells;
  j["reconstruct_split"] = ro.reconstructSplit;
  j["reconstruction_split_cells"] = rr.stats.reconstructionSplitCells;
  j["reconstruct_refine"] = switchName(a.reconstructRefine);
  j["reconstruction_refined_cells"] = rr.stats.reconstructionRefinedCells;
  j["max_depth"] = a.maxDepth;
  j["tonemap"] = io::toneMapName(a.tonemap);
  j["exposure"] = a.exposure;
  j["time_total_s"] = total;
  j["time_load_s"] = ls.loadSeconds;
  j["time_accel_s"] = ls.accelSeconds;
  j["time_lights_s"] = ls.lightSeconds;
  j["time_tree_s"] = forest.buildSeconds;
  j["time_render_s"] = rr.stats.seconds;
  j["primary_rays"] = rr.stats.primaryRays;
  j["secondary_rays"] = rr.stats.secondaryRays;
  j["shadow_rays"] = es.shadowRays;
  // Thread-seconds in shadow rays (estimated from a timed sample) and in light evaluation
  // as a whole; their ratio is the share the rays leave to the cut's own work.
  j["time_shadow_rays_s"] = es.shadowRaySeconds();
  j["time_lighting_s"] = es.lightingSeconds();
  j["shadow_ray_share"] = es.lightingSeconds() > 0 ? es.shadowRaySeconds() / es.lightingSeconds() : 0.0;
  j["rays_per_second"] = rr.stats.seconds > 0 ? double(allRays) / rr.stats.seconds : 0;
  j["shading_points"] = es.shadingPoints;
  j["lights"] = lightCountsJson(scene.lights());
  j["avg_lights_per_shading_point"] = perPoint;
  j["avg_shadow_rays_per_shading_point"] = raysPerPoint;
  j["bounds_evaluated"] = es.boundsEvaluated;
  nlohmann::json hist = nlohmann::json::array();
  for (size_t i = 0; i < es.cutHistogram.size(); ++i) {
    if (!es.cutHistogram[i]) continue;
    uint64_t lo = i == 0 ? 0 : (uint64_t(1) << (i - 1)), hi = (uint64_t(1) << i) - 1;
    hist.push_back({{"min", lo}, {"max", hi}, {"count", es.cutHistogram[i]}});
  }
  j["cut_histogram"] = hist;
  if (method != lightcuts::Method::Brute) {
    j["tree_builder"] = lightcuts::treeBuilderName(r.treeBuilder);
    j["tree_nodes"] = forest.nodeCount();
    j["tree_count"] = forest.trees.size();
    j["tree_memory_bytes"] = forest.memoryBytes();
  }
  j["object_lights"] = objectLightsJson(ls.objectLights);
  j["environment_lights"] = environmentLightsJson(ls.environmentLights);
  j["vpls"] = {{"paths", ls.vpls.paths}, {"count", ls.vpls.vpls}, {"time_s", ls.vpls.seconds},
               {"clamp_distance", ls.vpls.clampDistance}};
  j["vpl_clamped_fraction"] = clampedFraction;
  j["caustic_lights"] = ls.caustics.lights;
  j["caustics"] = {{"paths", ls.caustics.paths},
                   {"lights", ls.caustics.lights},
                   {"kind", io::causticLightKindName(ls.caustics.kind)},
                   {"time_s", ls.caustics.seconds},
                   {"mean_radius", ls.caustics.meanRadius},
                   {"power", {ls.caustics.power.x, ls.caustics.power.y, ls.caustics.power.z}}};
  if (ref.pixels > 0) {
    j["reference"] = {{"pixels", ref.pixels},
                      {"brute_seconds", ref.bruteSeconds},
                      {"brute_seconds_estimate", ref.bruteSecondsEstimate},
                      {"test_seconds", ref.testSeconds},
                      {"speedup_estimate", rr.stats.seconds > 0 ? ref.bruteSecondsEstimate / rr.stats.seconds : 0},
                      {"mean_relative_error", ref.meanRelativeError},
                      {"p99_relative_error", ref.p99RelativeError},
                      {"max_relative_error", ref.maxRelativeError},
                      {"fraction_over_2pct", ref.fractionOver2pct},
                      {"fraction_over_threshold", ref.fractionOver2pct},
                      {"threshold", render::ReferenceStats::kThreshold},
                      {"brute_lights_per_shading_point", ref.bruteLightsPerShadingPoint}};
    nlohmann::json worst = nlohmann::json::array();
    for (const render::ReferenceStats::Pixel& p : ref.worst)
      worst.push_back({{"x", p.x}, {"y", p.y}, {"reference", p.reference}, {"test", p.test},
                       {"relative_error", p.relativeError}});
    j["reference"]["worst_pixels"] = worst;
  }
  if (r.perRank)
    j["mpi"] = {{"ranks", r.ranks}, {"load_balance", r.loadBalance}, {"per_rank", *r.perRank}};
  return j;
}

void printRenderSummary(const RenderReport& r) {
  const RenderArgs& a = r.args;
  const LoadedScene& ls = r.loaded;
  const scene::Scene& scene = *ls.scene;
  const lightcuts::LightForest& forest = r.forest;
  const lightcuts::Method method = r.method;
  const render::RenderOptions& ro = r.options;
  const render::RenderResult& rr = r.result;
  const auto& es = rr.stats.eval;
  const auto [perPoint, raysPerPoint, allRays] = rates(rr.stats);
  const render::ReferenceStats& ref = rr.stats.reference;
  const float error = r.error;
  const LightSet& L = scene.lights();
  fmt::print("scene      {} ({} objects, {} triangles)\n", a.scene, scene.shapes().size(), scene.triangleCount());
  fmt::print("lights     {}\n", lightCountsLine(L));
  if (ls.vpls.vpls)
    fmt::print("vpls       {} from {} paths in {}; clamp at {:.4g} removes {:.1f}% of their light\n", ls.vpls.vpls,
               ls.vpls.paths, formatSeconds(ls.vpls.seconds), ls.vpls.clampDistance, 100 * r.clampedFraction);
  if (ls.caustics.paths)
    fmt::print("caustics   {} {} lights from {} paths in {} (footprint {:.4g}); shadow rays stop at glass\n",
               ls.caustics.lights, io::causticLightKindName(ls.caustics.kind), ls.caustics.paths,
               formatSeconds(ls.caustics.seconds), ls.caustics.meanRadius);
  if (method == lightcuts::Method::Brute)
    fmt::print("method     brute force\n");
  else
    fmt::print("method     {} (tree {}: {} nodes, {:.1f} MiB, built in {}), error {}{}, max cut {}\n",
               lightcuts::methodName(method), lightcuts::treeBuilderName(r.treeBuilder), forest.nodeCount(),
               double(forest.memoryBytes()) / (1 << 20), formatSeconds(forest.buildSeconds), error,
               method == lightcuts::Method::Lightcuts
                   ? fmt::format(" ({} criterion)", lightcuts::cutCriterionName(a.criterion))
                   : std::string(),
               a.maxCut);
  fmt::print("image      {}x{}, {} spp{} -> {}\n", a.width, a.height, a.spp,
             ro.spp == 1 && ro.aa == render::AntiAliasing::Adaptive
                 ? fmt::format(", adaptive antialiasing: {} pixels ({:.1f}%) re-sampled {} times",
                               formatCount(double(rr.stats.aaPixels)),
                               100.0 * double(rr.stats.aaPixels) / (double(a.width) * double(a.height)), ro.aaSamples)
                 : std::string(),
             a.out);
  if (r.perRank) {
    std::string tiles, busy;
    for (const auto& rank : *r.perRank) {
      tiles += fmt::format("{}{}", tiles.empty() ? "" : " / ", rank.at("tiles").get<uint64_t>());
      busy += fmt::format("{}{:.2f}", busy.empty() ? "" : " / ", rank.at("time_tiles_s").get<double>());
    }
    int threads = (*r.perRank)[0].at("threads").get<int>();
    fmt::print("mpi        {} ranks x {} thread{}: tiles {}, busy {} s; load balance {:.0f}%\n", r.ranks,
               threads, threads == 1 ? "" : "s", tiles, busy, 100 * r.loadBalance);
  }
  if (ro.reconstructSpacing == 1)
    fmt::print("recon.     full lightcuts at every pixel centre; {} sub-samples rebuilt from them, {} got full cuts\n",
               formatCount(double(es.reconstructedPoints)), formatCount(double(rr.stats.reconstructionFallbacks)));
  if (ro.reconstructSpacing > 1)
    fmt::print("recon.     full lightcuts every {} pixels ({} samples{}{}); {} points rebuilt from them, {} got full cuts\n",
               ro.reconstructSpacing, formatCount(double(rr.stats.reconstructionSamples)),
               ro.reconstructCoarseSpacing > 0
                   ? fmt::format("; {} cells of {} kept whole where their samples agree",
                                 formatCount(double(rr.stats.reconstructionCoarseCells)), ro.reconstructCoarseSpacing)
                   : std::string(),
               rr.stats.reconstructionSplitCells > 0
                   ? fmt::format("; {} split where they disagree", formatCount(double(rr.stats.reconstructionSplitCells)))
                   : std::string(),
               formatCount(double(es.reconstructedPoints)), formatCount(double(rr.stats.reconstructionFallbacks)));
  fmt::print("time       {} total: load {}, accel {}, lights {}, tree {}, render {}{}\n", formatSeconds(r.totalSeconds),
             formatSeconds(ls.loadSeconds), formatSeconds(ls.accelSeconds), formatSeconds(ls.lightSeconds),
             formatSeconds(forest.buildSeconds), formatSeconds(rr.stats.seconds),
             ref.pixels > 0 ? ", reference " + formatSeconds(ref.bruteSeconds) : std::string());
  fmt::print("rays       {} primary, {} secondary, {} shadow ({} rays/s)\n", formatCount(double(rr.stats.primaryRays)),
             formatCount(double(rr.stats.secondaryRays)), formatCount(double(es.shadowRays)),
             formatCount(rr.stats.seconds > 0 ? double(allRays) / rr.stats.seconds : 0));
  fmt::print("per point  {:.1f} lights (cut size), {:.1f} shadow rays, over {} shading points\n", perPoint,
             raysPerPoint, formatCount(double(es.shadingPoints)));
  if (ref.pixels > 0) {
    double speedup = rr.stats.seconds > 0 ? ref.bruteSecondsEstimate / rr.stats.seconds : 0;
    fmt::print("reference  brute force at {} pixels: {:.1f} lights per point; full image would take ~{} -> speed-up ~{:.1f}x\n",
               ref.pixels, ref.bruteLightsPerShadingPoint, formatSeconds(ref.bruteSecondsEstimate), speedup);
    fmt::print("error      mean {:.2f}%, p99 {:.2f}%, max {:.2f}%{}, {:.2f}% of sampled pixels over 2%\n",
               100 * ref.meanRelativeError, 100 * ref.p99RelativeError, 100 * ref.maxRelativeError,
               ref.worst.empty() ? std::string() : fmt::format(" at pixel ({}, {})", ref.worst[0].x, ref.worst[0].y),
               100 * ref.fractionOver2pct);
  }
}

}  // namespace lc::app
