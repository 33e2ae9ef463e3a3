#include "app/scene_loader.h"

#include <chrono>

#include "app/interrupt.h"
#include "app/progress.h"
#include "core/file_util.h"
#include "io/obj_loader.h"
#include "io/ray_parser.h"

namespace lc::app {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

LoadedScene loadScene(const std::string& path, const LoadOptions& o) {
  LoadedScene out;
  auto t0 = Clock::now();
  io::SceneDesc desc;
  if (fileExtension(path) == "obj") {
    ProgressBar bar("scene", o.quiet);
    desc = io::loadObjScene(path, o.limits, &out.objDescription, [&](double f) { bar.update(f); });
    bar.finish();
  } else {
    io::ParseOptions po;
    po.lenient = o.lenient;
    po.emissionDensity = o.emissionDensity;
    po.defaultAttenuation = o.defaultAttenuation;
    po.limits = o.limits;
    ProgressBar bar("scene", o.quiet);
    po.progress = [&](double f) { bar.update(f); };
    desc = io::parseRayFile(path, po);
    bar.finish();
  }
  out.warnings = desc.warnings;
  out.loadSeconds = since(t0);

  auto t1 = Clock::now();
  scene::BuildOptions bo;
  bo.limits = o.limits;
  bo.threads = o.threads;
  bo.linearizeSrgbTextures = o.linearizeSrgbTextures;
  bo.occluders = o.occluders;
  bo.planarFaces = o.planarFaces;
  {
    ProgressBar bar("accel", o.quiet);
    bo.progress = [&](double f) { bar.update(f); };
    out.scene = scene::Scene::build(desc, bo);
    bar.finish();
  }
  out.accelSeconds = since(t1);

  auto t2 = Clock::now();
  std::optional<InterruptScope> interrupts;
  if (o.interruptible) interrupts.emplace();
  lights::ObjectLightOptions olo = o.objectLights;
  olo.maxLights = o.limits.maxLights;
  if (o.interruptible) olo.cancel = &interruptFlag();
  {
    ProgressBar bar("object lights", o.quiet);
    olo.progress = [&](double f) { bar.update(f); };
    out.objectLights = lights::addObjectLights(*out.scene, olo);
    bar.finish();
  }
  if (!out.scene->environments().empty()) {
    // Before the VPLs: instant radiosity shoots from the environment's lights too.
    lights::EnvironmentLightOptions eo;
    eo.count = o.envLights;
    eo.seed = o.envSeed;
    eo.maxLights = o.limits.maxLights;
    if (o.interruptible) eo.cancel = &interruptFlag();
    ProgressBar bar("environment lights", o.quiet);
    eo.progress = [&](double f) { bar.update(f); };
    out.environmentLights = lights::addEnvironmentLights(*out.scene, eo);
    bar.finish();
  }
  if (o.gi) {
    lights::VplOptions v;
    const auto& ir = desc.instantRadiosity;
    if (ir) {
      if (ir->vpls) v.count = *ir->vpls;
      if (ir->bounces) v.bounces = *ir->bounces;
      if (ir->normalize) v.normalize = *ir->normalize;
      if (ir->clamp) v.clamp = *ir->clamp;
      if (ir->seed) v.seed = *ir->seed;
    }
    if (o.vplCount) v.count = *o.vplCount;
    if (o.bounces) v.bounces = *o.bounces;
    if (o.vplNormalize) v.normalize = *o.vplNormalize;
    if (o.vplClamp) v.clamp = *o.vplClamp;
    if (o.vplSeed) v.seed = *o.vplSeed;
    v.maxVpls = o.limits.maxVpls;
    if (o.interruptible) v.cancel = &interruptFlag();
    if (v.count > 0) {
      ProgressBar bar("VPLs", o.quiet);
      v.progress = [&](double f) { bar.update(f); };
      out.vpls = lights::addVpls(*out.scene, v);
      bar.finish();
    }
  }
  {
    // After the VPLs: caustic paths start from the scene's lights, not from VPLs.
    lights::CausticOptions c;
    const auto& ir = desc.instantRadiosity;
    if (ir) {
      if (ir->caustics) c.paths = *ir->caustics;
      if (ir->causticLights) c.kind = *ir->causticLights;
      if (ir->seed) c.seed = *ir->seed;
    }
    if (o.causticPaths) c.paths = *o.causticPaths;
    if (o.causticLights) c.kind = *o.causticLights;
    if (o.causticSmoothing) c.smoothing = *o.causticSmoothing;
    if (o.vplSeed) c.seed = *o.vplSeed;
    c.maxLights = o.limits.maxLights;
    if (o.interruptible) c.cancel = &interruptFlag();
    if (c.paths > 0) {
      ProgressBar bar("caustics", o.quiet);
      c.progress = [&](double f) { bar.update(f); };
      out.caustics = lights::addCaustics(*out.scene, c);
      bar.finish();
    }
  }
  // A signal caught after the last check: stop here, not after the next phase.
  if (o.interruptible && interruptFlag().load()) throw Interrupted();
  interrupts.reset();
  if (out.scene->lights().size() > o.limits.maxLights)
    throw Error("the scene has " + std::to_string(out.scene->lights().size()) +
                " lights, more than --max-lights (" + std::to_string(o.limits.maxLights) + ")");
  out.lightSeconds = since(t2);
  return out;
}

}  // namespace lc::app
