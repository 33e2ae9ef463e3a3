// `lightcuts render`: load, light, render, write the image, report.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <optional>
#include <thread>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/distributed.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "app/scene_loader.h"
#include "app/scene_options.h"
#include "app/summary.h"
#include "app/warnings.h"
#include "core/file_util.h"
#include "core/memory_budget.h"
#include "io/colormap.h"
#include "io/image.h"
#include "lightcuts/evaluator.h"
#include "render/reference_pixels.h"
#include "render/renderer.h"

namespace lc::app {

namespace {

constexpr int kMaxImageSide = 1 << 16;  // --width, --height and sizes from the aspect ratio
constexpr int kDefaultWidth = 512;      // when neither --width nor --height is given


struct RenderArgs {
  std::string scene;
  std::string out;
  int width = 0, height = 0;
  int spp = render::RenderOptions{}.spp;
  std::string aa = render::antiAliasingName(render::RenderOptions{}.aa);
  int aaSamples = render::RenderOptions{}.aaSamples;
  std::string aov;  // comma-separated kAovNames
  int threads = 0;
  int maxDepth = 5;
  std::string stats;
  bool quiet = false;
  std::string method = "lightcuts";
  std::string tree;  // default: by method
  float error = -1;  // default: by method
  int maxCut = lightcuts::CutOptions{}.maxCut;
  int stochasticCut = lightcuts::CutOptions{}.stochasticCut;
  std::string criterion = "total";
  std::string estimator = "first-order";
  bool visibilityProbes = lightcuts::CutOptions{}.visibilityProbes;
  std::string cutHeatmap;
  int referencePixels = 0;
  std::string errorFloor = "auto";
  std::string reconstruct = "auto";
  std::string reconstructCoarse = "auto";
  std::string tonemap = "srgb";
  float exposure = 0;  // EV: 8-bit outputs scale linear values by 2^exposure
  uint64_t seed = 1;
  LoadOptions load;
};

// --error's defaults live with the cut options (lightcuts/evaluator.h).
constexpr float kLightcutsDefaultError = lightcuts::CutOptions{}.errorRatio;
constexpr float kCourseDefaultError = lightcuts::kCourseCutsDefaultError;

// --reconstruct auto: reconstruction cuts (every 4 pixels) from 512 x 512 pixels up, a
// full lightcut at every point below. A cell of 4 x 4 pixels covers four times the
// surface at 256 x 256 that it does at 512 x 512, and shadows thinner than a cell are what
// borrowed visibility misses: on the 100,000-light scaling scene at 256 x 256, 2.0% of
// pixels come out more than 2% off with them and 0.8% without (docs/LIGHTCUTS.md); small
// images are cheap either way.
constexpr int kAutoReconstructSpacing = 4;
constexpr int kAutoReconstructMinSide = 512;  // from kAutoReconstructMinSide^2 pixels up
int reconstructSpacing(const std::string& option, int width, int height) {
  if (option != "auto") return std::stoi(option);
  return int64_t(width) * height >= int64_t(kAutoReconstructMinSide) * kAutoReconstructMinSide ? kAutoReconstructSpacing
                                                                                               : 0;
}

// --reconstruct-coarse auto: cells twice the spacing where their corners agree (see
// RenderOptions::reconstructCoarseSpacing); on the green emitter a third fewer samples
// for the same error. N must be the spacing times a power of two, 0 = none.
constexpr int kAutoCoarseFactor = 2;
int reconstructCoarseSpacing(const std::string& option, int spacing) {
  if (spacing <= 1) return 0;
  if (option == "auto") return kAutoCoarseFactor * spacing;
  int c = std::stoi(option);
  if (c == 0) return 0;
  int m = spacing;
  while (m < c) m *= 2;
  if (m != c || c == spacing)
    throw Error(fmt::format("--reconstruct-coarse {}: must be 0 or the reconstruction spacing ({}) times 2, 4, 8, ...",
                            c, spacing));
  return c;
}

// --aov: extra EXR layers, by name, with their channels.
struct AovKind {
  const char* name;
  std::vector<const char*> channels;
};
const std::vector<AovKind> kAovs = {{"albedo", {"R", "G", "B"}},
                                    {"normal", {"X", "Y", "Z"}},
                                    {"depth", {"Z"}},
                                    {"cut", {"Y"}},
                                    {"shadow_rays", {"Y"}}};

std::vector<std::string> parseAovs(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    bool known = false;
    for (const AovKind& k : kAovs) known = known || name == k.name;
    if (!known)
      throw Error(fmt::format("--aov: unknown output {} (use albedo, normal, depth, cut, shadow_rays, "
                              "comma-separated)",
                              quoteInput(name)));
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// The EXR channels of the requested AOVs ("albedo.R", ..., "depth.Z").
std::vector<io::WriteOptions::Channel> aovChannels(const std::vector<std::string>& names, const scene::Scene& scene,
                                                   const render::RenderOptions& ro, const render::RenderResult& rr) {
  std::vector<io::WriteOptions::Channel> out;
  const bool primary = std::any_of(names.begin(), names.end(),
                                   [](const std::string& n) { return n == "albedo" || n == "normal" || n == "depth"; });
  render::PixelAovs pa;
  if (primary) pa = render::primaryAovs(scene, ro);
  const size_t n = size_t(ro.width) * size_t(ro.height);
  for (const std::string& name : names) {
    if (name == "cut" || name == "shadow_rays") {
      out.push_back({name + ".Y", name == "cut" ? rr.cutSize : rr.shadowRays});
      continue;
    }
    if (name == "depth") {
      out.push_back({"depth.Z", pa.depth});
      continue;
    }
    const std::vector<Vec3>& v = name == "albedo" ? pa.albedo : pa.normal;
    const char* axes = name == "albedo" ? "RGB" : "XYZ";
    for (int c = 0; c < 3; ++c) {
      io::WriteOptions::Channel ch{name + "." + axes[c], std::vector<float>(n)};
      for (size_t i = 0; i < n; ++i) ch.values[i] = v[i][c];
      out.push_back(std::move(ch));
    }
  }
  return out;
}

// Text metadata of the output image: what made it and from what.
io::TextMetadata metadata(const RenderArgs& a) {
  return {{"Software", "lightcuts " LC_VERSION}, {"Scene", a.scene}, {"Command line", commandLine()}};
}

std::string defaultOutput(const std::string& scene) {
  std::string stem = scene;
  size_t slash = stem.find_last_of('/');
  if (slash != std::string::npos) stem = stem.substr(slash + 1);
  size_t dot = stem.find_last_of('.');
  if (dot != std::string::npos && dot > 0) stem = stem.substr(0, dot);
  return stem + ".png";
}

// Every rank's part of a distributed render, as JSON: rank 0 puts it under "mpi" in --stats
// and adds the counters ("counters", removed there) to the job's totals.
nlohmann::json rankJson(const Cluster& cluster, int threads, const LoadedScene& ls, double treeSeconds,
                        const render::RenderResult& rr) {
  const auto& st = rr.stats;
  uint64_t rays = st.primaryRays + st.secondaryRays + st.eval.shadowRays;
  return {{"rank", cluster.rank()},
          {"host", cluster.host()},
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

int renderJob(RenderArgs& a, Cluster* cluster);

int runRender(RenderArgs& a) {
  // Under an MPI launcher (mpirun, srun) every process runs this; see app/distributed.h.
  std::unique_ptr<Cluster> cluster = joinCluster();
  int status = 0;
  if (!cluster || cluster->rank() == 0) {
    status = renderJob(a, cluster.get());
  } else {
    try {
      status = renderJob(a, cluster.get());
    } catch (const Error& e) {
      // Every rank reads the same input, so rank 0 most likely fails the same way: give it
      // a moment to say so and end the job (which ends this rank too), rather than print
      // the message once per rank.
      std::this_thread::sleep_for(std::chrono::seconds(2));
      throw Error(fmt::format("rank {} on {}: {}", cluster->rank(), cluster->host(), e.what()));
    }
  }
  // A clean end only when every rank is done; otherwise this process's exit (non-zero)
  // ends the job.
  if (status == 0 && cluster) cluster->finish();
  return status;
}

int renderJob(RenderArgs& a, Cluster* cluster) {
  auto t0 = std::chrono::steady_clock::now();
  const bool distributed = cluster && cluster->size() > 1;
  const bool root = !cluster || cluster->rank() == 0;  // writes the image and reports
  if (!root) a.quiet = true;
  if (a.out.empty()) a.out = defaultOutput(a.scene);
  checkDistinctPaths({{a.scene, "the scene"}, {a.out, "-o"}, {a.stats, "--stats"}, {a.cutHeatmap, "--cut-heatmap"}});
  std::string ext = fileExtension(a.out);
  if (std::filesystem::is_directory(a.out)) throw Error("cannot write '" + a.out + "': it is a directory");
  if (ext.empty())
    throw Error("cannot write '" + a.out + "': no file extension to choose the format (use .png, .ppm, .bmp or .exr)");
  if (!io::isWritableImageExtension(ext))
    throw Error("cannot write '" + a.out + "': unknown image format '." + ext + "' (use .png, .ppm, .bmp or .exr)");
  const std::vector<std::string> aovs = a.aov.empty() ? std::vector<std::string>{} : parseAovs(a.aov);
  if (!aovs.empty() && ext != "exr")
    throw Error("--aov needs an .exr output (its layers are extra EXR channels); '" + a.out + "' is ." + ext);
  // Fail before a long render, not after it (only rank 0 writes).
  if (root) {
    checkWritable(a.out);
    if (!a.stats.empty()) checkWritable(a.stats);
    if (!a.cutHeatmap.empty()) checkWritable(a.cutHeatmap);
  }
  lightcuts::Method method = lightcuts::parseMethod(a.method);
  lightcuts::TreeBuildOptions tb;
  tb.builder = a.tree.empty() ? (method == lightcuts::Method::Course ? lightcuts::TreeBuilder::Course
                                                                    : lightcuts::TreeBuilder::Agglomerative)
                              : lightcuts::parseTreeBuilder(a.tree);
  tb.seed = a.seed;
  float error = a.error >= 0 ? a.error : (method == lightcuts::Method::Course ? kCourseDefaultError : kLightcutsDefaultError);
  if (!std::isfinite(error)) throw Error("--error must be a finite number >= 0");
  io::ToneMap tonemap = io::parseToneMap(a.tonemap);
  if (!std::isfinite(a.exposure)) throw Error("--exposure must be a finite number");

  a.load.threads = a.threads;
  a.load.objectLights.seed = a.seed;  // shifts the stratified object-light points
  a.load.envSeed = a.seed;            // shifts the environment lights' point set
  // sRGB texture maps (from MTL files) are linearised whenever the output is display-encoded
  // (srgb, filmic; the EXR of such a render too, so that both formats hold one linear image);
  // --tonemap clamp keeps the course renderer's look: textures and output as stored.
  a.load.linearizeSrgbTextures = tonemap != io::ToneMap::Clamp;
  a.load.quiet = a.quiet;
  a.load.interruptible = true;
  LoadedScene ls;
  try {
    ls = loadScene(a.scene, a.load);
  } catch (const Interrupted&) {
    // Stopped while making the lights: nothing rendered, nothing written.
    if (root) fmt::print(stderr, "lightcuts: interrupted; {} untouched\n", a.out);
    return interruptExitStatus();
  }
  scene::Scene& scene = *ls.scene;
  // The loader's warnings carry their location: "file:line:col: warning: ...".
  if (root)
    for (const std::string& w : ls.warnings) fmt::print(stderr, "lightcuts: {}\n", w);
  if (!ls.objDescription.empty() && !a.quiet)
    fmt::print(stderr, "OBJ input: added a default camera and lights:\n{}\n", ls.objDescription);

  // Image size: from the flags, completing the missing one from the aspect ratio.
  const auto& cam = scene.desc().camera;
  // In double, checked against the flags' bound before converting: an aspect ratio of 3e9
  // would otherwise overflow int (and wrap to a 1-pixel or negative size).
  double aspect = cam.aspectRatio ? double(*cam.aspectRatio) : 1.0;
  if (a.width <= 0 && a.height <= 0) a.width = kDefaultWidth;
  if (a.width <= 0 || a.height <= 0) {
    bool fromWidth = a.width > 0;
    double other = std::max(1.0, std::round(fromWidth ? a.width / aspect : a.height * aspect));
    if (!(other <= kMaxImageSide))
      throw Error(fmt::format("aspectratio {} makes the image {}: more than {} pixels {} (give both --width and --height)",
                              float(aspect),
                              fromWidth ? fmt::format("{}x{:.0f}", a.width, other)
                                        : fmt::format("{:.0f}x{}", other, a.height),
                              kMaxImageSide, fromWidth ? "high" : "wide"));
    (fromWidth ? a.height : a.width) = int(other);
  }
  if (uint64_t(a.width) * uint64_t(a.height) > a.load.limits.maxImagePixels)
    throw Error(fmt::format("an image of {}x{} exceeds --max-image-pixels ({})", a.width, a.height,
                            a.load.limits.maxImagePixels));
  processBudget().reserve(uint64_t(a.width) * uint64_t(a.height) * memory_cost::kPixel,
                          fmt::format("the {}x{} image's buffers", a.width, a.height));
  io::CameraDesc camera = cam;
  if (!ls.objDescription.empty() && a.width < a.height) {
    // The OBJ default camera fits the model's bounding sphere in its vertical field of view;
    // a portrait image would cut the sides, so the field is widened to fit it across instead.
    float half = std::tan(camera.fovDegrees * kPi / 360.0f) * float(a.height) / float(a.width);
    camera.fovDegrees = std::atan(half) * 360.0f / kPi;
  }
  scene.setCamera(scene::Camera::fromDesc(camera, float(a.width) / float(a.height)));
  // (after the checks above: an error is not preceded by warnings about a render that will not run)
  if (root && scene.lights().size() == 0)
    printWarning("the scene has no lights: only emissive and ambient colours will show (add a point_light, "
                 "directional_light, spot_light or area_light, or a luminosity to a material)");
  const bool objInput = fileExtension(a.scene) == "obj";
  if (root && objInput && !ls.objectLights.empty() && ls.vpls.vpls == 0 && a.load.gi && !a.load.vplCount)
    printHint("the OBJ's emissive materials light what they see directly, nothing bounces; --vpls 10000 adds "
              "indirect light (global illumination)");

  // Light tree and evaluator; oriented lights weigh their normal cones by the scene's size.
  tb.sceneDiagonal = scene.bounds().diagonal();
  lightcuts::LightForest forest;
  std::unique_ptr<lightcuts::LightEvaluator> evaluator;
  lightcuts::CutOptions co{error, a.maxCut, lightcuts::parseCutCriterion(a.criterion),
                           lightcuts::parseEstimator(a.estimator), a.visibilityProbes};
  co.stochasticCut = a.stochasticCut;
  co.seed = a.seed;
  if (method == lightcuts::Method::Brute) {
    evaluator = lightcuts::makeBruteForce(scene.lights());
  } else {
    ProgressBar bar("light tree", a.quiet);
    tb.progress = [&](double f) { bar.update(f); };
    forest = lightcuts::buildLightForest(scene.lights(), tb);
    bar.finish();
    evaluator = method == lightcuts::Method::Course         ? lightcuts::makeCourseCuts(scene.lights(), forest, co)
                : method == lightcuts::Method::Stochastic ? lightcuts::makeStochasticLightcuts(scene.lights(), forest, co)
                                                          : lightcuts::makeLightcuts(scene.lights(), forest, co);
  }

  render::RenderOptions ro;
  ro.width = a.width;
  ro.height = a.height;
  ro.spp = a.spp;
  ro.aa = render::parseAntiAliasing(a.aa);
  ro.aaSamples = a.aaSamples;
  ro.threads = a.threads;
  ro.maxDepth = a.maxDepth;
  ro.seed = a.seed;
  ro.referencePixels = a.referencePixels;
  // --error-floor: auto (< 0 to the renderer), 0 (none) or an absolute luminance.
  ro.errorFloor = a.errorFloor == "auto" ? -1.0f : std::stof(a.errorFloor);
  ro.reconstructSpacing = method == lightcuts::Method::Lightcuts ? reconstructSpacing(a.reconstruct, a.width, a.height) : 0;
  ro.reconstructCoarseSpacing = reconstructCoarseSpacing(a.reconstructCoarse, ro.reconstructSpacing);
  ro.cancel = &interruptFlag();
  std::unique_ptr<render::WorkShare> share;
  if (distributed) {
    share = cluster->workShare(&interruptFlag());
    ro.share = share.get();
  }
  ProgressBar bar("rendering", a.quiet);
  ro.progress = [&](double f) { bar.update(f); };
  ProgressBar refBar("reference pixels", a.quiet);
  ro.referenceProgress = [&](double f) { refBar.update(f); };
  std::optional<InterruptScope> interrupts(std::in_place);
  render::RenderResult rr = render::render(scene, *evaluator, ro);
  bar.finish();
  refBar.finish();
  interrupts.reset();

  if (rr.interrupted || interruptFlag().load()) {
    if (!root) {
      // Rank 0 keeps what it gathered. The launcher passes a Ctrl-C on to every rank as
      // SIGTERM, and when one rank exits it kills the others at once (Open MPI's mpirun):
      // so wait here, and let rank 0 write the partial image in the second mpirun gives
      // before SIGKILL.
      std::this_thread::sleep_for(std::chrono::seconds(3));
      return interruptExitStatus();
    }
    // Leave the requested output alone; keep what was rendered in OUT.partial.exr.
    std::string partial = a.out + ".partial.exr";
    io::WriteOptions po;
    po.metadata = metadata(a);
    io::writeImage(partial, rr.image, po);
    fmt::print(stderr, "lightcuts: interrupted; {} untouched, partial image in {}\n", a.out, partial);
    if (distributed && interruptSignal() == SIGTERM)
      fmt::print(stderr, "lightcuts: (under MPI, SIGTERM comes from the launcher: the job was interrupted, or "
                         "another rank failed)\n");
    return interruptExitStatus();
  }

  // A distributed render: every rank's statistics to rank 0, added to the job's totals.
  nlohmann::json perRank = nlohmann::json::array();
  double loadBalance = 1;
  if (distributed) {
    int threads = a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency());
    std::vector<std::string> all =
        cluster->gather(rankJson(*cluster, threads, ls, forest.buildSeconds, rr).dump(), &interruptFlag());
    if (!root) return 0;
    if (all.size() != size_t(cluster->size())) throw Error("interrupted while gathering the ranks' statistics");
    double sumTiles = 0, maxTiles = 0;
    for (size_t r = 0; r < all.size(); ++r) {
      nlohmann::json j = nlohmann::json::parse(all[r]);
      if (r > 0) addRenderCounters(rr.stats, j.at("counters"));
      j.erase("counters");
      sumTiles += j.at("time_tiles_s").get<double>();
      maxTiles = std::max(maxTiles, j.at("time_tiles_s").get<double>());
      perRank.push_back(std::move(j));
    }
    // Mean over max of the time each rank spent until its last tile: 1 when all finish together.
    loadBalance = maxTiles > 0 ? sumTiles / double(all.size()) / maxTiles : 1;
  }


  io::WriteOptions wo;
  wo.tonemap = tonemap;
  wo.exposure = a.exposure;
  wo.metadata = metadata(a);
  wo.channels = aovChannels(aovs, scene, ro, rr);
  if (ext != "exr") {
    wo.metadata.emplace_back("Tone map", a.tonemap);
    wo.metadata.emplace_back("Exposure", fmt::format("{:g}", a.exposure));
  }
  io::writeImage(a.out, rr.image, wo);
  if (scene.lights().size() > 0) {
    // Judged as displayed: the 8-bit output's tone map, or sRGB for an EXR viewed as usual.
    const auto& es = rr.stats.eval;
    RenderFacts facts{scene.lights().size(), rr.stats.primaryRays, es.shadingPoints, es.shadowRays, es.occludedRays};
    std::string w = blackImageWarning(rr.image, ext == "exr" ? io::ToneMap::Srgb : tonemap, a.exposure, facts);
    if (!w.empty()) printWarning(w);
  }
  if (!a.cutHeatmap.empty()) {
    float maxCut = 1;
    for (float c : rr.cutSize) maxCut = std::max(maxCut, c);
    io::Image hm = io::heatmap(rr.cutSize, a.width, a.height, 0, maxCut, "lights per pixel (cut size)");
    io::writeImage(a.cutHeatmap, hm);
  }
  double clampedFraction = ls.vpls.vpls ? render::vplClampedFraction(scene, ro) : 0;
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const auto& es = rr.stats.eval;
  double perPoint = es.shadingPoints ? double(es.cutNodes) / double(es.shadingPoints) : 0;
  double raysPerPoint = es.shadingPoints ? double(es.shadowRays) / double(es.shadingPoints) : 0;
  uint64_t allRays = rr.stats.primaryRays + rr.stats.secondaryRays + es.shadowRays;
  const render::ReferenceStats& ref = rr.stats.reference;

  if (!a.stats.empty()) {
    nlohmann::json j;
    j["scene"] = a.scene;
    j["output"] = a.out;
    j["width"] = a.width;
    j["height"] = a.height;
    j["spp"] = a.spp;
    j["aa"] = a.spp == 1 ? a.aa : "off";
    j["aa_samples"] = a.aaSamples;
    j["aa_pixels"] = rr.stats.aaPixels;
    j["aa_sub_samples"] = rr.stats.aaSubSamples;
    j["threads"] = a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency());
    j["method"] = lightcuts::methodName(method);
    j["error_threshold"] = error;
    j["max_cut"] = a.maxCut;
    j["error_floor"] = rr.stats.errorFloor;
    j["error_floor_pixels"] = rr.stats.errorFloorPixels;
    j["cut_criterion"] = a.criterion;
    j["estimator"] = a.estimator;
    j["visibility_probes"] = switchName(a.visibilityProbes);
    j["probed_clusters"] = es.probedClusters;
    j["probe_rays"] = es.probeRays;
    j["occluded_shadow_rays"] = es.occludedRays;
    j["hidden_clusters"] = es.hiddenClusters;
    j["group_probes"] = es.groupProbes;
    j["failed_group_probes"] = es.failedGroupProbes;
    j["reconstruct_spacing"] = ro.reconstructSpacing;
    j["reconstruct_coarse_spacing"] = ro.reconstructCoarseSpacing;
    j["reconstruction_samples"] = rr.stats.reconstructionSamples;
    j["reconstructed_points"] = es.reconstructedPoints;
    j["reconstruction_fallbacks"] = rr.stats.reconstructionFallbacks;
    j["reconstruction_coarse_cells"] = rr.stats.reconstructionCoarseCells;
    j["max_depth"] = a.maxDepth;
    j["tonemap"] = a.tonemap;
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
      j["tree_builder"] = lightcuts::treeBuilderName(tb.builder);
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
                     {"kind", lights::causticLightKindName(ls.caustics.kind)},
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
    }
    if (distributed)
      j["mpi"] = {{"ranks", cluster->size()}, {"load_balance", loadBalance}, {"per_rank", perRank}};
    std::string text = j.dump(2) + "\n";
    writeFileAtomically(a.stats, [&](const std::string& tmp) {
      FILE* f = std::fopen(tmp.c_str(), "wb");
      if (!f) throw Error("cannot write '" + a.stats + "'");
      bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
      ok = (std::fclose(f) == 0) && ok;
      if (!ok) throw Error("cannot write '" + a.stats + "'");
    });
  }

  if (!a.quiet) {
    const LightSet& L = scene.lights();
    fmt::print("scene      {} ({} objects, {} triangles)\n", a.scene, scene.shapes().size(), scene.triangleCount());
    fmt::print("lights     {}\n", lightCountsLine(L));
    if (ls.vpls.vpls)
      fmt::print("vpls       {} from {} paths in {}; clamp at {:.4g} removes {:.1f}% of their light\n", ls.vpls.vpls,
                 ls.vpls.paths, formatSeconds(ls.vpls.seconds), ls.vpls.clampDistance, 100 * clampedFraction);
    if (ls.caustics.paths)
      fmt::print("caustics   {} {} lights from {} paths in {} (footprint {:.4g}); shadow rays stop at glass\n",
                 ls.caustics.lights, lights::causticLightKindName(ls.caustics.kind), ls.caustics.paths,
                 formatSeconds(ls.caustics.seconds), ls.caustics.meanRadius);
    if (method == lightcuts::Method::Brute)
      fmt::print("method     brute force\n");
    else
      fmt::print("method     {} (tree {}: {} nodes, {:.1f} MiB, built in {}), error {}{}, max cut {}\n",
                 lightcuts::methodName(method), lightcuts::treeBuilderName(tb.builder), forest.nodeCount(),
                 double(forest.memoryBytes()) / (1 << 20), formatSeconds(forest.buildSeconds), error,
                 method == lightcuts::Method::Lightcuts ? " (" + a.criterion + " criterion)" : "", a.maxCut);
    fmt::print("image      {}x{}, {} spp{} -> {}\n", a.width, a.height, a.spp,
               ro.spp == 1 && ro.aa == render::AntiAliasing::Adaptive
                   ? fmt::format(", adaptive antialiasing: {} pixels ({:.1f}%) re-sampled {} times",
                                 formatCount(double(rr.stats.aaPixels)),
                                 100.0 * double(rr.stats.aaPixels) / (double(a.width) * double(a.height)), ro.aaSamples)
                   : std::string(),
               a.out);
    if (distributed) {
      std::string tiles, busy;
      for (const auto& r : perRank) {
        tiles += fmt::format("{}{}", tiles.empty() ? "" : " / ", r.at("tiles").get<uint64_t>());
        busy += fmt::format("{}{:.2f}", busy.empty() ? "" : " / ", r.at("time_tiles_s").get<double>());
      }
      int threads = perRank[0].at("threads").get<int>();
      fmt::print("mpi        {} ranks x {} thread{}: tiles {}, busy {} s; load balance {:.0f}%\n", cluster->size(),
                 threads, threads == 1 ? "" : "s", tiles, busy, 100 * loadBalance);
    }
    if (ro.reconstructSpacing > 1)
      fmt::print("recon.     full lightcuts every {} pixels ({} samples{}); {} points rebuilt from them, {} got full cuts\n",
                 ro.reconstructSpacing, formatCount(double(rr.stats.reconstructionSamples)),
                 ro.reconstructCoarseSpacing > 0
                     ? fmt::format("; {} cells of {} kept whole where their samples agree",
                                   formatCount(double(rr.stats.reconstructionCoarseCells)), ro.reconstructCoarseSpacing)
                     : std::string(),
                 formatCount(double(es.reconstructedPoints)), formatCount(double(rr.stats.reconstructionFallbacks)));
    fmt::print("time       {} total: load {}, accel {}, lights {}, tree {}, render {}{}\n", formatSeconds(total),
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
      fmt::print("error      mean {:.2f}%, p99 {:.2f}%, max {:.2f}%, {:.2f}% of sampled pixels over 2%\n",
                 100 * ref.meanRelativeError, 100 * ref.p99RelativeError, 100 * ref.maxRelativeError,
                 100 * ref.fractionOver2pct);
    }
  }
  return 0;
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  // Every default below is read from where it lives (RenderArgs' initialisers, the
  // constants above), so the help cannot drift from what the command does.
  const RenderArgs& d = *a;
  const std::string output = "Output", image = "Image", cuts = "Lightcuts", recon = "Reconstruction";
  CLI::App* c = app.add_subcommand("render", "Render a .ray or .obj scene to an image");
  c->add_option("scene", a->scene, "Scene file (.ray or .obj)")->required();
  c->add_option("-o,--output", a->out,
                "Output image: .png .ppm .bmp (8-bit) or .exr (float); default the scene's name with .png, in the "
                "current folder")
      ->group(output);
  c->add_option("--stats", a->stats, "Write statistics as JSON to this file; default none")->group(output);
  c->add_option("--cut-heatmap", a->cutHeatmap,
                "Write the per-pixel cut size, colour-mapped with a legend, to this PNG; default none")
      ->group(output);
  c->add_option("--tonemap", a->tonemap,
                fmt::format("8-bit output (.png .ppm .bmp): srgb (the linear image sRGB-encoded for display), filmic "
                            "(highlights roll off: Narkowicz's ACES fit, then sRGB) or clamp (values stored as they "
                            "are, the course renderer's look; sRGB textures not linearised); .exr stays linear; "
                            "default {}",
                            d.tonemap))
      ->check(CLI::IsMember({"clamp", "srgb", "filmic"}))
      ->group(output);
  c->add_option("--exposure", a->exposure,
                fmt::format("Exposure in stops for 8-bit output: linear values are scaled by 2^EV before the tone "
                            "map (.exr is written unscaled); default {:g}",
                            d.exposure))
      ->check(CLI::Range(-64.0f, 64.0f))
      ->group(output);
  c->add_flag("-q,--quiet", a->quiet, fmt::format("No progress bar or summary; default {}", d.quiet ? "on" : "off"))
      ->group(output);
  c->add_option("--width", a->width,
                fmt::format("Image width in pixels; default {}, or from --height and the aspect ratio", kDefaultWidth))
      ->check(CLI::Range(1, kMaxImageSide))
      ->group(image);
  c->add_option("--height", a->height, "Image height in pixels; default the width / the camera's aspect ratio")
      ->check(CLI::Range(1, kMaxImageSide))
      ->group(image);
  c->add_option("--spp", a->spp,
                fmt::format("Samples per pixel, stratified (1 = the pixel centre, antialiased by --aa); more = that "
                            "many at every pixel, --aa aside; default {}",
                            d.spp))
      ->check(CLI::Range(1, 65536))
      ->group(image);
  {
    const render::RenderOptions ro;
    c->add_option("--aa", a->aa,
                  fmt::format("Antialiasing with --spp 1: adaptive (a pixel whose centre ray differs from a "
                              "neighbour's in shape, in normal by more than {:.0f} degrees, or in luminance by more "
                              "than {:g}% is re-sampled with --aa-samples stratified sub-samples) or off (the pixel "
                              "centre only); default {}",
                              std::acos(ro.aaNormalCos) * 180 / kPi, 100 * ro.aaContrast, d.aa))
        ->check(CLI::IsMember({"adaptive", "off"}))
        ->group(image);
    c->add_option("--aa-samples", a->aaSamples,
                  fmt::format("Adaptive antialiasing: sub-samples at a re-sampled pixel, with its centre a g x g "
                              "stratified grid: 8 (3 x 3), 24 (5 x 5) or 48 (7 x 7); default {}",
                              d.aaSamples))
        ->check(CLI::IsMember({8, 24, 48}))
        ->group(image);
  }
  c->add_option("--aov", a->aov,
                "Extra outputs as layers of the .exr output, comma-separated: albedo (albedo.R/G/B: the diffuse "
                "colour at the pixel centre's hit), normal (normal.X/Y/Z: its shading normal, facing the camera), "
                "depth (depth.Z: distance along the camera ray, inf for none), cut (cut.Y: lights in the cut per "
                "sample), shadow_rays (shadow_rays.Y: per sample); the image stays R, G, B; default none")
      ->group(output);
  c->add_option("--max-depth", a->maxDepth, fmt::format("Reflection/refraction recursion depth; default {}", d.maxDepth))
      ->check(CLI::Range(0, 64))
      ->group(image);
  c->add_option("--threads", a->threads,
                fmt::format("Worker threads (0 = all cores); default {}", d.threads))
      ->check(CLI::Range(0, 1024))
      ->group(image);
  // The VPLs are shot while the scene loads: an explicit --seed goes there too, over the
  // scene's instant_radiosity seed.
  auto setSeed = [a](const uint64_t& v) {
    a->seed = v;
    a->load.vplSeed = v;
  };
  c->add_option_function<uint64_t>("--seed", setSeed,
                                   fmt::format("Random seed (sampling, representatives, VPL paths, object-light placement; overrides "
                                               "instant_radiosity's seed); default {}", d.seed))
      ->group(image);
  c->add_option("--method", a->method,
                fmt::format("Direct lighting: lightcuts (Walter et al. 2005), seed (the course project's cuts), "
                            "stochastic (stochastic lightcuts, Yuksel 2019: unbiased, noisy, no error bound; average "
                            "with --spp) or brute; default {}", d.method))
      ->check(CLI::IsMember({"lightcuts", "seed", "course", "stochastic", "brute"}))
      ->group(cuts);
  c->add_option("--stochastic-cut", a->stochasticCut,
                fmt::format("--method stochastic: clusters per shading point, one light drawn in each; default {}",
                            lightcuts::CutOptions{}.stochasticCut))
      ->check(CLI::Range(1, 1 << 20))
      ->group(cuts);
  c->add_option("--tree", a->tree,
                fmt::format("Light tree: walter (agglomerative) or seed (k-d split); default {} for --method seed, "
                            "else {}", lightcuts::treeBuilderName(lightcuts::TreeBuilder::Course),
                            lightcuts::treeBuilderName(lightcuts::TreeBuilder::Agglomerative)))
      ->check(CLI::IsMember({"walter", "agglomerative", "seed", "course"}))
      ->group(cuts);
  c->add_option("--error", a->error,
                fmt::format("Error threshold: relative bound for lightcuts (default {}); radius/distance for seed "
                            "(default {})", kLightcutsDefaultError, kCourseDefaultError))
      ->check(CLI::Range(0.0, 1e6))
      ->group(cuts);
  c->add_option("--max-cut", a->maxCut, fmt::format("Most nodes in one cut; default {}", d.maxCut))
      ->check(CLI::Range(1, 1 << 30))
      ->group(cuts);
  c->add_option("--error-floor", a->errorFloor,
                fmt::format("Lightcuts: luminance below which --error is an absolute error (a cut stops within error x "
                            "max(estimate, floor)); auto = {} x the mean luminance of a {} x {} pre-pass (half the "
                            "floor of compare's relative error), 0 = none (as published); default {}",
                            render::kAutoErrorFloorFraction, render::kErrorFloorGrid, render::kErrorFloorGrid,
                            d.errorFloor))
      ->check(CLI::IsMember({"auto"}) | CLI::Range(0.0, 1e30))
      ->group(cuts);
  c->add_option("--cut-criterion", a->criterion,
                fmt::format("When a lightcut stops: total (every bound below error x estimate and the root-sum-square "
                            "of the error spreads below 1.6 x that) or walter (every bound below error x estimate, as "
                            "published); default {}", d.criterion))
      ->check(CLI::IsMember({"total", "walter"}))
      ->group(cuts);
  c->add_option("--estimator", a->estimator,
                fmt::format("A cluster's estimate (lightcuts): first-order (its representative's, less the first-order "
                            "change from the cluster's mean light, where smooth) or representative (as published); "
                            "default {}", d.estimator))
      ->check(CLI::IsMember({"first-order", "representative"}))
      ->group(cuts);
  addSwitch(*c, "--visibility-probes", a->visibilityProbes,
            fmt::format("Lightcuts: before refining a cluster whose representative is hidden, test the corners of "
                        "its box; when one convex object hides them all, the cluster stays in the cut as hidden "
                        "(on) or not (off, as published); default {}", switchName(d.visibilityProbes)))
      ->group(cuts);
  c->add_option("--reference-pixels", a->referencePixels,
                fmt::format("Also run brute force at K pixels: report the measured error and the estimated "
                            "brute-force time; default {} (none)", d.referencePixels))
      ->check(CLI::Range(0, 1 << 24))
      ->group(cuts);
  c->add_option("--reconstruct", a->reconstruct,
                fmt::format("Reconstruction cuts (lightcuts): full cuts every N pixels in x and y, primary hits "
                            "between them borrow their visibility (Walter et al. 2005 sec. 5); 0 = a full cut at "
                            "every point; default {}: {} for images of {} x {} pixels or more, else 0",
                            d.reconstruct, kAutoReconstructSpacing, kAutoReconstructMinSide, kAutoReconstructMinSide))
      ->check(CLI::IsMember({"auto"}) | CLI::Range(0, 1024))
      ->group(recon);
  c->add_option("--reconstruct-coarse", a->reconstructCoarse,
                fmt::format("Reconstruction cuts: cells of M pixels first, kept whole where their four corner samples "
                            "lie on one surface and disagree about little of their light, else split down to N; M = N "
                            "times a power of two, 0 = off; default {} = {}N",
                            d.reconstructCoarse, kAutoCoarseFactor))
      ->check(CLI::IsMember({"auto"}) | CLI::Range(0, 1 << 16))
      ->group(recon);
  addSceneOptions(*c, a->load);
  c->callback([a] {
    if (!parseOnly()) exitStatus() = runRender(*a);
  });
}

}  // namespace lc::app
