// `lightcuts render`: set up (load, light, size, evaluator), render, report (the image,
// then --stats and the summary, summary.h).
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
#include "app/render_args.h"
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

// --error's defaults live with the cut options (lightcuts/evaluator.h).
constexpr float kLightcutsDefaultError = lightcuts::CutOptions{}.errorRatio;
constexpr float kCourseDefaultError = lightcuts::kCourseCutsDefaultError;

// The share of a 32 x 32 grid of camera rays through the image that hit any surface.
double cameraHitFraction(const scene::Scene& scene) {
  constexpr int kGrid = 32;
  const scene::Camera& cam = scene.camera();
  int hits = 0;
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      scene::Ray ray{cam.eye, normalize(cam.direction((float(x) + 0.5f) / kGrid, (float(y) + 0.5f) / kGrid)), 0, kInf};
      scene::Hit h;
      hits += scene.intersect(ray, h);
    }
  return double(hits) / (kGrid * kGrid);
}

// --reconstruct auto: reconstruction cuts (every 4 pixels) from 512 x 512 pixels up, a
// full lightcut at every point below. A cell of 4 x 4 pixels covers four times the
// surface at 256 x 256 that it does at 512 x 512, and shadows thinner than a cell are what
// borrowed visibility misses: on the 100,000-light scaling scene at 256 x 256, 2.0% of
// pixels come out more than 2% off with them and 0.8% without (docs/LIGHTCUTS.md). Small
// images are not always cheap without them: the church at 256 x 256 (313,666 full cuts,
// 1,545 shadow rays a point) took 109 s against ~53 s at 512 x 512 with them.
// Larger images keep the cell's share of the view instead of its size in pixels: the
// spacing doubles each time the image's side (the square root of its pixel count) does,
// 8 from 1024 x 1024 (and 1920 x 1080) up, so a cell spans the surface that one of 4
// spans at 512 x 512, the size the accuracy was measured at; the finer cells of a fixed
// 4 sampled the same shadows more densely than they need (docs/LIGHTCUTS.md).
// Below that size a full cut at every point, sub-samples included: rebuilding only the
// sub-samples from the pixel centres (--reconstruct 1) made the 100,000-light room at 64 x
// 64 1.5x faster at the same error, but put 0.4-1.7% of pixels over 2% on unseen scenes of
// fine geometry at 128 x 128 (a library's shelves, a theatre's seats behind a railing),
// against 0.01-0.34%, and 0.2-0.8% at 256 x 256 against 0-0.22% (docs/LIGHTCUTS.md,
// "Sub-samples rebuilt from pixel centres").
constexpr int kAutoReconstructSpacing = 4;
constexpr int kAutoReconstructMinSide = 512;  // from kAutoReconstructMinSide^2 pixels up
int reconstructSpacing(const std::string& option, int width, int height) {
  if (option != "auto") return std::stoi(option);
  const int64_t pixels = int64_t(width) * height;
  int64_t side = kAutoReconstructMinSide;
  if (pixels < side * side) return 0;
  int spacing = kAutoReconstructSpacing;
  while (pixels >= 4 * side * side) {
    side *= 2;
    spacing *= 2;
  }
  return spacing;
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

// --aov: extra EXR layers, by name (their channels: aovChannels). A constant array, no
// allocation at start-up.
constexpr const char* kAovNames[] = {"albedo", "normal", "depth", "cut", "shadow_rays", "samples"};

std::vector<std::string> parseAovs(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    bool known = false;
    for (const char* k : kAovNames) known = known || name == k;
    if (!known)
      throw Error(fmt::format("--aov: unknown output {} (use albedo, normal, depth, cut, shadow_rays, samples, "
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
    if (name == "samples") {
      // Camera samples taken at each pixel: --spp, or 1 and, where adaptive antialiasing
      // re-sampled the pixel, its sub-samples too: where the render spent its extra rays.
      const float flagged = float(1 + ro.aaSamples);
      std::vector<float> v(n, float(ro.spp));
      if (ro.spp == 1 && ro.aa == render::AntiAliasing::Adaptive)
        for (size_t i = 0; i < n && i < rr.aaFlagged.size(); ++i) v[i] = rr.aaFlagged[i] ? flagged : 1.0f;
      out.push_back({"samples.Y", std::move(v)});
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

int renderJob(RenderArgs& a, Cluster* cluster);

// How long a rank other than 0 waits, after an error, for rank 0 to end the job.
constexpr int kNonRootErrorDelaySeconds = 10;

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
      // time to say so and end the job (which ends this rank too), rather than print the
      // message once per rank. Two seconds were not always enough under the sanitizers on
      // a loaded machine (rank 1's message came too, 1 run in ~50); the wait only delays
      // the rare error that rank 0 does not share (a file missing on one node).
      std::this_thread::sleep_for(std::chrono::seconds(kNonRootErrorDelaySeconds));
      throw Error(fmt::format("rank {} on {}: {}", cluster->rank(), cluster->host(), e.what()));
    }
  }
  // A clean end only when every rank is done; otherwise this process's exit (non-zero)
  // ends the job.
  if (status == 0 && cluster) cluster->finish();
  return status;
}

// What a render is made of, from set-up to report.
struct RenderSetup {
  bool root = true;          // this process writes the image and reports
  bool distributed = false;  // more than one process renders
  std::string ext;           // the output's format
  std::vector<std::string> aovs;
  lightcuts::Method method = lightcuts::Method::Lightcuts;
  lightcuts::TreeBuildOptions tb;
  float error = 0;  // --error, resolved by method
  LoadedScene ls;
  lightcuts::LightForest forest;
  std::unique_ptr<lightcuts::LightEvaluator> evaluator;
  render::RenderOptions ro;
};

// The outputs and the options read before anything loads: a mistake fails at once, not
// after a long render.
void checkArgs(RenderArgs& a, RenderSetup& s) {
  if (a.out.empty()) a.out = defaultOutput(a.scene);
  checkDistinctPaths({{a.scene, "the scene"}, {a.out, "-o"}, {a.stats, "--stats"}, {a.cutHeatmap, "--cut-heatmap"}});
  std::string& ext = s.ext;
  ext = fileExtension(a.out);
  if (std::filesystem::is_directory(a.out)) throw Error("cannot write '" + a.out + "': it is a directory");
  if (ext.empty())
    throw Error("cannot write '" + a.out + "': no file extension to choose the format (use .png, .ppm, .bmp or .exr)");
  if (!io::isWritableImageExtension(ext))
    throw Error("cannot write '" + a.out + "': unknown image format '." + ext + "' (use .png, .ppm, .bmp or .exr)");
  s.aovs = a.aov.empty() ? std::vector<std::string>{} : parseAovs(a.aov);
  if (!s.aovs.empty() && ext != "exr")
    throw Error("--aov needs an .exr output (its layers are extra EXR channels); '" + a.out + "' is ." + ext);
  // Fail before a long render, not after it (only rank 0 writes).
  if (s.root) {
    checkWritable(a.out);
    if (!a.stats.empty()) checkWritable(a.stats);
    if (!a.cutHeatmap.empty()) checkWritable(a.cutHeatmap);
  }
  s.method = a.method;
  s.tb.builder = a.tree ? *a.tree
                        : s.method == lightcuts::Method::Course ? lightcuts::TreeBuilder::Course
                                                                : lightcuts::TreeBuilder::Agglomerative;
  s.tb.seed = a.seed;
  s.error = a.error >= 0 ? a.error
                         : (s.method == lightcuts::Method::Course ? kCourseDefaultError : kLightcutsDefaultError);
  if (!std::isfinite(s.error)) throw Error("--error must be a finite number >= 0");
  if (!std::isfinite(a.exposure)) throw Error("--exposure must be a finite number");
}

// The image size from the flags, completing the missing one from the aspect ratio.
void resolveImageSize(RenderArgs& a, const io::CameraDesc& cam) {
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
}

// The light tree and the evaluator; oriented lights weigh their normal cones by the
// scene's size.
void buildEvaluator(const RenderArgs& a, RenderSetup& s) {
  const scene::Scene& scene = *s.ls.scene;
  s.tb.sceneDiagonal = scene.bounds().diagonal();
  lightcuts::CutOptions co{s.error, a.maxCut, a.criterion, a.estimator, a.visibilityProbes, a.clearClusters};
  co.secondSamples = a.secondSamples;
  co.stochasticCut = a.stochasticCut;
  co.seed = a.seed;
  if (s.method == lightcuts::Method::Brute) {
    s.evaluator = lightcuts::makeBruteForce(scene.lights());
  } else {
    ProgressBar bar("light tree", a.quiet);
    s.tb.progress = [&](double f) { bar.update(f); };
    s.forest = lightcuts::buildLightForest(scene.lights(), s.tb);
    bar.finish();
    s.tb.progress = nullptr;  // (the bar ends here)
    s.evaluator = s.method == lightcuts::Method::Course
                      ? lightcuts::makeCourseCuts(scene.lights(), s.forest, co)
                  : s.method == lightcuts::Method::Stochastic
                      ? lightcuts::makeStochasticLightcuts(scene.lights(), s.forest, co)
                      : lightcuts::makeLightcuts(scene.lights(), s.forest, co);
  }
}

render::RenderOptions renderOptions(const RenderArgs& a, lightcuts::Method method) {
  render::RenderOptions ro;
  ro.width = a.width;
  ro.height = a.height;
  ro.spp = a.spp;
  ro.aa = a.aa;
  ro.aaSamples = a.aaSamples;
  ro.aaExtrapolationProbe = a.aaExtrapolationProbe;
  ro.aaPixelSamples = a.aaPixelSamples;
  ro.threads = a.threads;
  ro.maxDepth = a.maxDepth;
  ro.seed = a.seed;
  ro.referencePixels = a.referencePixels;
  // --error-floor: auto (< 0 to the renderer), 0 (none) or an absolute luminance.
  ro.errorFloor = a.errorFloor == "auto" ? -1.0f : std::stof(a.errorFloor);
  ro.reconstructSpacing = method == lightcuts::Method::Lightcuts ? reconstructSpacing(a.reconstruct, a.width, a.height) : 0;
  ro.reconstructCoarseSpacing = reconstructCoarseSpacing(a.reconstructCoarse, ro.reconstructSpacing);
  ro.reconstructSplit = a.reconstructSplit;
  ro.reconstructRefine = a.reconstructRefine;
  return ro;
}

// Set-up: checks, the scene with its lights, the image size and camera, the evaluator and
// the render's options. False when interrupted while making the lights.
bool setUpRender(RenderArgs& a, Cluster* cluster, RenderSetup& s) {
  s.distributed = cluster && cluster->size() > 1;
  s.root = !cluster || cluster->rank() == 0;
  if (!s.root) a.quiet = true;
  checkArgs(a, s);

  a.load.threads = a.threads;
  a.load.objectLights.seed = a.seed;  // shifts the stratified object-light points
  a.load.envSeed = a.seed;            // shifts the environment lights' point set
  // sRGB texture maps (from MTL files) are linearised whenever the output is display-encoded
  // (srgb, filmic; the EXR of such a render too, so that both formats hold one linear image);
  // --tonemap clamp keeps the course renderer's look: textures and output as stored.
  a.load.linearizeSrgbTextures = a.tonemap != io::ToneMap::Clamp;
  // Only lightcuts' clear clusters query the occluder index (scene/occluders.h).
  a.load.occluders = a.method == lightcuts::Method::Lightcuts && a.clearClusters;
  // and only its visibility probes ask about the meshes' flat faces (scene/planar_faces.h).
  a.load.planarFaces = a.method == lightcuts::Method::Lightcuts && a.visibilityProbes;
  a.load.quiet = a.quiet;
  a.load.interruptible = true;
  try {
    s.ls = loadScene(a.scene, a.load);
  } catch (const Interrupted&) {
    // Stopped while making the lights: nothing rendered, nothing written.
    if (s.root) fmt::print(stderr, "lightcuts: interrupted; {} untouched\n", a.out);
    return false;
  }
  scene::Scene& scene = *s.ls.scene;
  // The loader's warnings carry their location: "file:line:col: warning: ...".
  if (s.root)
    for (const std::string& w : s.ls.warnings) fmt::print(stderr, "lightcuts: {}\n", w);
  if (!s.ls.objDescription.empty() && !a.quiet)
    fmt::print(stderr, "OBJ input: added a default camera and lights:\n{}\n", s.ls.objDescription);

  const auto& cam = scene.cameraDesc();
  resolveImageSize(a, cam);
  processBudget().reserve(uint64_t(a.width) * uint64_t(a.height) * memory_cost::kPixel,
                          fmt::format("the {}x{} image's buffers", a.width, a.height));
  io::CameraDesc camera = cam;
  if (!s.ls.objDescription.empty() && a.width < a.height) {
    // The OBJ default camera fits the model's bounding sphere in its vertical field of view;
    // a portrait image would cut the sides, so the field is widened to fit it across instead.
    float half = std::tan(camera.fovDegrees * kPi / 360.0f) * float(a.height) / float(a.width);
    camera.fovDegrees = std::atan(half) * 360.0f / kPi;
  }
  scene.setCamera(scene::Camera::fromDesc(camera, float(a.width) / float(a.height)));
  // (after the checks above: an error is not preceded by warnings about a render that will not run)
  if (s.root && scene.lights().size() == 0)
    printWarning("the scene has no lights: only emissive and ambient colours will show (add a point_light, "
                 "directional_light, spot_light or area_light, or a luminosity to a material)");
  const bool objInput = fileExtension(a.scene) == "obj";
  if (s.root && objInput && !s.ls.objectLights.empty() && s.ls.vpls.vpls == 0 && a.load.gi && !a.load.vplCount)
    printHint("the OBJ's emissive materials light what they see directly, nothing bounces; --vpls 10000 adds "
              "indirect light (global illumination)");

  buildEvaluator(a, s);
  s.ro = renderOptions(a, s.method);
  return true;
}

// What the render step leaves for the report.
struct RenderRun {
  render::RenderResult rr;
  // A distributed render: every rank's statistics (rankStatsJson), and the load balance.
  nlohmann::json perRank = nlohmann::json::array();
  double loadBalance = 1;
};

// Render: the image (its tiles shared with the other ranks of a distributed render), with
// progress bars and Ctrl-C, then every rank's statistics to rank 0. An exit status when
// the job ends here (interrupted; or a rank other than 0, its part done).
std::optional<int> renderImage(const RenderArgs& a, Cluster* cluster, RenderSetup& s, RenderRun& run) {
  render::RenderOptions& ro = s.ro;
  ro.cancel = &interruptFlag();
  std::unique_ptr<render::WorkShare> share;
  if (s.distributed) {
    share = cluster->workShare(&interruptFlag());
    ro.share = share.get();
  }
  ProgressBar bar("rendering", a.quiet);
  ro.progress = [&](double f) { bar.update(f); };
  ProgressBar refBar("reference pixels", a.quiet);
  ro.referenceProgress = [&](double f) { refBar.update(f); };
  std::optional<InterruptScope> interrupts(std::in_place);
  run.rr = render::render(*s.ls.scene, *s.evaluator, ro);
  bar.finish();
  refBar.finish();
  interrupts.reset();
  // (the bars go out of scope here: the options must not call them later)
  ro.progress = nullptr;
  ro.referenceProgress = nullptr;
  render::RenderResult& rr = run.rr;

  if (rr.interrupted || interruptFlag().load()) {
    if (!s.root) {
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
    if (s.distributed && interruptSignal() == SIGTERM)
      fmt::print(stderr, "lightcuts: (under MPI, SIGTERM comes from the launcher: the job was interrupted, or "
                         "another rank failed)\n");
    return interruptExitStatus();
  }

  // A distributed render: every rank's statistics to rank 0, added to the job's totals.
  if (s.distributed) {
    int threads = a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency());
    std::vector<std::string> all = cluster->gather(
        rankStatsJson(cluster->rank(), cluster->host(), threads, s.ls, s.forest.buildSeconds, rr).dump(),
        &interruptFlag());
    if (!s.root) return 0;
    if (all.size() != size_t(cluster->size())) throw Error("interrupted while gathering the ranks' statistics");
    double sumTiles = 0, maxTiles = 0;
    for (size_t r = 0; r < all.size(); ++r) {
      nlohmann::json j = nlohmann::json::parse(all[r]);
      if (r > 0) addRenderCounters(rr.stats, j.at("counters"));
      j.erase("counters");
      sumTiles += j.at("time_tiles_s").get<double>();
      maxTiles = std::max(maxTiles, j.at("time_tiles_s").get<double>());
      run.perRank.push_back(std::move(j));
    }
    // Mean over max of the time each rank spent until its last tile: 1 when all finish together.
    run.loadBalance = maxTiles > 0 ? sumTiles / double(all.size()) / maxTiles : 1;
  }
  return std::nullopt;
}

// Report: the image with its AOVs, the cut heatmap, then --stats and the terminal summary
// (summary.h).
void reportRender(const RenderArgs& a, Cluster* cluster, const RenderSetup& s, const RenderRun& run,
                  std::chrono::steady_clock::time_point t0) {
  const scene::Scene& scene = *s.ls.scene;
  const render::RenderResult& rr = run.rr;
  io::WriteOptions wo;
  wo.tonemap = a.tonemap;
  wo.exposure = a.exposure;
  wo.threads = a.threads;  // the render's threads compress the EXR
  wo.metadata = metadata(a);
  wo.channels = aovChannels(s.aovs, scene, s.ro, rr);
  if (s.ext != "exr") {
    wo.metadata.emplace_back("Tone map", io::toneMapName(a.tonemap));
    wo.metadata.emplace_back("Exposure", fmt::format("{:g}", a.exposure));
  }
  io::writeImage(a.out, rr.image, wo);
  if (scene.lights().size() > 0) {
    // Judged as displayed: the 8-bit output's tone map, or sRGB for an EXR viewed as usual.
    const auto& es = rr.stats.eval;
    RenderFacts facts{scene.lights().size(), rr.stats.primaryRays, es.shadingPoints, es.shadowRays, es.occludedRays};
    facts.cameraHitFraction = cameraHitFraction(scene);
    std::string w = blackImageWarning(rr.image, s.ext == "exr" ? io::ToneMap::Srgb : a.tonemap, a.exposure, facts);
    if (!w.empty()) printWarning(w);
    w = maxCutWarning(es.cutsAtMaxCut, es.shadingPoints, a.maxCut);
    if (!w.empty()) printWarning(w);
  }
  if (!a.cutHeatmap.empty()) {
    float maxCut = 1;
    for (float c : rr.cutSize) maxCut = std::max(maxCut, c);
    io::Image hm = io::heatmap(rr.cutSize, a.width, a.height, 0, maxCut, "lights per pixel (cut size)");
    io::writeImage(a.cutHeatmap, hm);
  }

  RenderReport report{a, s.ls, s.method, s.tb.builder, s.error, s.forest, s.ro, rr};
  report.clampedFraction = s.ls.vpls.vpls ? render::vplClampedFraction(scene, s.ro) : 0;
  report.totalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (s.distributed) {
    report.ranks = cluster->size();
    report.loadBalance = run.loadBalance;
    report.perRank = &run.perRank;
  }
  if (!a.stats.empty()) {
    std::string text = renderStatsJson(report).dump(2) + "\n";
    writeFileAtomically(a.stats, [&](const std::string& tmp) {
      FILE* f = std::fopen(tmp.c_str(), "wb");
      if (!f) throw Error("cannot write '" + a.stats + "'");
      bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
      ok = (std::fclose(f) == 0) && ok;
      if (!ok) throw Error("cannot write '" + a.stats + "'");
    });
  }
  if (!a.quiet) printRenderSummary(report);
}

int renderJob(RenderArgs& a, Cluster* cluster) {
  const auto t0 = std::chrono::steady_clock::now();
  RenderSetup s;
  if (!setUpRender(a, cluster, s)) return interruptExitStatus();
  RenderRun run;
  if (std::optional<int> status = renderImage(a, cluster, s, run)) return *status;
  reportRender(a, cluster, s, run, t0);
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
  // Options with named values take their names, their check and the help's list from their
  // enums' tables (addEnumOption, app/scene_options.h).
  addEnumOption(*c, "--tonemap", io::kToneMapNames, [a](io::ToneMap t) { a->tonemap = t; },
                fmt::format("8-bit output (.png .ppm .bmp): {}; .exr stays linear; default {}",
                            enumHelp(io::kToneMapNames), io::toneMapName(d.tonemap)))
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
                fmt::format("Samples per pixel, multi-jittered (1 = the pixel centre, antialiased by --aa); more = that "
                            "many at every pixel, --aa aside; default {}",
                            d.spp))
      ->check(CLI::Range(1, 65536))
      ->group(image);
  {
    addEnumOption(*c, "--aa", render::kAntiAliasingNames, [a](render::AntiAliasing aa) { a->aa = aa; },
                  fmt::format("Antialiasing with --spp 1: {}; default {}", render::antiAliasingHelp(),
                              render::antiAliasingName(d.aa)))
        ->group(image);
    c->add_option("--aa-samples", a->aaSamples,
                  fmt::format("Adaptive antialiasing: sub-samples at a re-sampled pixel, with its centre a g x g "
                              "multi-jittered grid: 8 (3 x 3), 24 (5 x 5), 48 (7 x 7) or 80 (9 x 9); from 24 a plain surface is shaded once "
                              "per cell of a 3 x 3 grid, its other sub-samples measuring coverage; default {}",
                              d.aaSamples))
        ->check(CLI::IsMember({8, 24, 48, 80}))
        ->group(image);
    addSwitch(*c, "--aa-extrapolation-probe", a->aaExtrapolationProbe,
              fmt::format("Adaptive antialiasing under reconstruction cuts: a sub-sample beyond the samples it "
                          "borrows from sends a few short rays for a surface near it, and takes a full lightcut if "
                          "one is there (edge-on faces, slats, creases: fewer pixels over --error, 3-30% more shadow "
                          "rays); off borrows regardless; default {}",
                          switchName(d.aaExtrapolationProbe)))
        ->group(image);
    addSwitch(*c, "--aa-pixel-samples", a->aaPixelSamples,
              fmt::format("Adaptive antialiasing under reconstruction cuts: a sub-sample that takes a full "
                          "lightcut becomes a sample for the rest of its pixel and the next ones (creases and "
                          "edges: fewer full cuts); off, each such sub-sample takes its own; default {}",
                          switchName(d.aaPixelSamples)))
        ->group(image);
  }
  c->add_option("--aov", a->aov,
                "Extra outputs as layers of the .exr output, comma-separated: albedo (albedo.R/G/B: the diffuse "
                "colour at the pixel centre's hit), normal (normal.X/Y/Z: its shading normal, facing the camera), "
                "depth (depth.Z: distance along the camera ray, inf for none), cut (cut.Y: lights in the cut per "
                "sample), shadow_rays (shadow_rays.Y: per sample), samples (samples.Y: camera samples taken at the pixel, "
                "showing where antialiasing re-sampled); the image stays R, G, B; default none")
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
  addEnumOption(*c, "--method", lightcuts::kMethodNames, [a](lightcuts::Method m) { a->method = m; },
                fmt::format("Direct lighting: {}; default {}", enumHelp(lightcuts::kMethodNames),
                            lightcuts::methodName(d.method)))
      ->group(cuts);
  c->add_option("--stochastic-cut", a->stochasticCut,
                fmt::format("--method stochastic: clusters per shading point, one light drawn in each; default {}",
                            lightcuts::CutOptions{}.stochasticCut))
      ->check(CLI::Range(1, 1 << 20))
      ->group(cuts);
  addEnumOption(*c, "--tree", lightcuts::kTreeBuilderNames, [a](lightcuts::TreeBuilder b) { a->tree = b; },
                fmt::format("Light tree: {}; default {} for --method {}, else {}", enumHelp(lightcuts::kTreeBuilderNames),
                            lightcuts::treeBuilderName(lightcuts::TreeBuilder::Course),
                            lightcuts::methodName(lightcuts::Method::Course),
                            lightcuts::treeBuilderName(lightcuts::TreeBuilder::Agglomerative)))
      ->group(cuts);
  c->add_option("--error", a->error,
                fmt::format("Error threshold: relative bound for lightcuts (default {}); radius/distance for seed "
                            "(default {})", kLightcutsDefaultError, kCourseDefaultError))
      ->check(CLI::Range(0.0, 1e6))
      ->group(cuts);
  c->add_option("--max-cut", a->maxCut, fmt::format("Most nodes in one cut (a cut stopped there has not met --error: counted in "
                            "--stats as cuts_at_max_cut, with a warning over {:g}% of the cuts); default {}",
                            100 * kMaxCutShare, d.maxCut))
      ->check(CLI::Range(1, 1 << 30))
      ->group(cuts);
  c->add_option("--error-floor", a->errorFloor,
                fmt::format("Lightcuts: luminance below which --error is an absolute error (a cut stops within error x "
                            "max(estimate, floor)); auto = {} x the mean luminance of a {} x {} pre-pass of cuts within max(--error, {}%) "
                            "(half the floor of compare's relative error), 0 = none (as published); default {}",
                            render::kAutoErrorFloorFraction, render::kErrorFloorGrid, render::kErrorFloorGrid,
                            100 * render::kErrorFloorPrePassError, d.errorFloor))
      ->check(CLI::IsMember({"auto"}) | CLI::Range(0.0, 1e30))
      ->group(cuts);
  addEnumOption(*c, "--cut-criterion", lightcuts::kCutCriterionNames,
                [a](lightcuts::CutCriterion k) { a->criterion = k; },
                fmt::format("When a lightcut stops: {}; default {}", enumHelp(lightcuts::kCutCriterionNames),
                            lightcuts::cutCriterionName(d.criterion)))
      ->group(cuts);
  addEnumOption(*c, "--estimator", lightcuts::kEstimatorNames, [a](lightcuts::Estimator e) { a->estimator = e; },
                fmt::format("A cluster's estimate (lightcuts): {}; default {}", enumHelp(lightcuts::kEstimatorNames),
                            lightcuts::estimatorName(d.estimator)))
      ->group(cuts);
  addSwitch(*c, "--visibility-probes", a->visibilityProbes,
            fmt::format("Lightcuts: before refining a cluster whose representative is hidden, test the corners of "
                        "its box (boxes, spheres, capped cylinders, squares, convex meshes and the flat faces of other "
                        "meshes answer without rays); "
                        "when one convex object hides them all, the cluster stays in the cut as hidden (on) or not "
                        "(off, as published); "
                        "default {}", switchName(d.visibilityProbes)))
      ->group(cuts);
  addSwitch(*c, "--clear-clusters", a->clearClusters,
            fmt::format("Lightcuts: test a cluster whose representative is visible for being visible as a whole, "
                        "without rays (every surface's bounding volume apart from the hull of the point and the "
                        "cluster); such clusters are refined without shadow rays and carry no visibility error "
                        "(on; with --error-floor auto, not where fewer than one in 16 of its pre-pass's tests passed"
                        ") or every representative casts its ray (off, as published); default {}",
                        switchName(d.clearClusters)))
      ->group(cuts);
  addSwitch(*c, "--second-samples", a->secondSamples,
            fmt::format("Lightcuts: before a cut stops, a cluster whose representative is visible and whose estimate "
                        "holds over {:g} of the error limit sends one ray to a second of its lights; where that "
                        "one is hidden the cluster is refined as one on a shadow boundary (on), or its "
                        "representative stands for it alone (off); default {}",
                        lightcuts::kSecondSampleShare, switchName(d.secondSamples)))
      ->group(cuts);
  c->add_option("--reference-pixels", a->referencePixels,
                fmt::format("Also run brute force at K pixels: report the measured error, the worst pixels (--stats: "
                            "reference.worst_pixels) and the estimated brute-force time; default {} (none)",
                            d.referencePixels))
      ->check(CLI::Range(0, 1 << 24))
      ->group(cuts);
  c->add_option("--reconstruct", a->reconstruct,
                fmt::format("Reconstruction cuts (lightcuts): full cuts every N pixels in x and y, primary hits "
                            "between them borrow their visibility (Walter et al. 2005 sec. 5); 0 = a full cut at "
                            "every point; 1 = a full cut at every pixel centre, antialiasing's sub-samples borrow (faster "
                            "where many pixels are re-sampled, less accurate on fine geometry); default {}: {} for "
                            "images of {} x {} pixels or more (twice that each time the image's side doubles: 8 at "
                            "1920 x 1080), else 0",
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
  c->add_option("--reconstruct-split", a->reconstructSplit,
                fmt::format("Reconstruction cuts: a cell of N pixels or less whose corner samples lie on one surface "
                            "splits in four (new samples) when the lights they disagree about hold more than this share "
                            "of their light: dense shadow edges, where thin shadows between the samples are likely; "
                            "1 = never; default {}",
                            d.reconstructSplit))
      ->check(CLI::Range(0.0f, 1.0f))
      ->group(recon);
  addSwitch(*c, "--reconstruct-refine", a->reconstructRefine,
            fmt::format("Reconstruction cuts: where a point's probe finds hidden a group of lights holding over "
                        "--error of its light that all its samples saw (a shadow they stepped over), its cell splits "
                        "in four with new samples, and an antialiasing sub-sample takes a full lightcut (thin shelves "
                        "and posts: fewer pixels over --error, 5-11% more shadow rays); off, only that point "
                        "re-traces the group; default {}",
                        switchName(d.reconstructRefine)))
      ->group(recon);
  addSceneOptions(*c, a->load);
  c->callback([a] {
    if (!parseOnly()) exitStatus() = runRender(*a);
  });
}

}  // namespace lc::app
