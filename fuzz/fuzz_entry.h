// The entry points of the fuzz targets, shared by the libFuzzer binaries (fuzz/*_fuzz.cpp)
// and by the regression test that replays data/regressions/<target>/ in the normal suite
// (src/app/fuzz_regression_test.cpp). Each entry point takes arbitrary bytes and must
// either return or throw lc::Error; anything else (another exception, a crash, a
// sanitizer report, a hang) is a bug.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"
#include "io/colormap.h"
#include "io/image.h"
#include "io/image_metrics.h"
#include "io/obj_loader.h"
#include "io/ray_parser.h"
#include "lights/object_lights.h"
#include "lights/vpl.h"
#include "scene/scene.h"

namespace lc::fuzz {

// Small limits so that one input cannot take seconds or gigabytes: every limit is still
// exercised (inputs that exceed them must fail cleanly).
inline Limits tinyLimits() {
  Limits l;
  l.maxLights = 10'000;
  l.maxTriangles = 100'000;
  l.maxVertices = 100'000;
  l.maxImagePixels = 1 << 16;
  l.maxTexturePixels = 1 << 16;
  l.maxNesting = 200;
  l.maxVpls = 1'000;
  l.maxFileBytes = 1 << 22;
  return l;
}

// A scratch directory for inputs that must be files; one per process, removed at exit.
inline const std::string& scratchDir() {
  static const std::string dir = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "lc-fuzz-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) std::abort();
    static std::string keep = tmpl;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(keep, ec);
    });
    return tmpl;
  }();
  return dir;
}

inline std::string writeScratch(const std::string& name, std::string_view bytes) {
  std::string path = scratchDir() + "/" + name;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size()) std::abort();
  std::fclose(f);
  return path;
}

// .ray text -> SceneDesc. Relative paths (textures, obj_mesh) resolve against `baseDir`.
inline void parseRay(const uint8_t* data, size_t size, const std::string& baseDir) {
  io::ParseOptions o;
  o.limits = tinyLimits();
  o.lenient = size > 0 && (data[0] & 1);  // both modes: strict and --lenient
  std::string text(reinterpret_cast<const char*>(data), size);
  (void)io::parseRayString(text, "fuzz.ray", baseDir, o);
}

// OBJ + MTL: the input is the OBJ text, optionally followed by a line "%%MTL%%" and the
// MTL text. The OBJ is written to f.obj and the MTL to f.mtl beside it (the seeds say
// `mtllib f.mtl`; any other name is looked up and not found, which is a warning).
inline constexpr std::string_view kMtlSeparator = "\n%%MTL%%\n";
inline void loadObj(const uint8_t* data, size_t size) {
  std::string_view all(reinterpret_cast<const char*>(data), size);
  size_t sep = all.find(kMtlSeparator);
  std::string_view obj = all.substr(0, sep);
  std::string_view mtl = sep == std::string_view::npos ? std::string_view() : all.substr(sep + kMtlSeparator.size());
  writeScratch("f.mtl", mtl);
  std::string path = writeScratch("f.obj", obj);
  Limits limits = tinyLimits();
  limits.maxTriangles = limits.maxVertices = 20'000;
  (void)io::loadObj(path, SourceLoc{}, io::MaterialDesc{}, limits);
}

// Any image file (bmp/png/jpg/tga/hdr/ppm/exr: readImage dispatches on the content).
inline void readImage(const uint8_t* data, size_t size) {
  std::string path = writeScratch("img", std::string_view(reinterpret_cast<const char*>(data), size));
  bool srgb = size > 0 && (data[size - 1] & 1);
  (void)io::readImage(path, srgb, tinyLimits().maxTexturePixels);
}

// A whole scene: parse, build (textures, Embree), object lights and VPLs on a tiny budget.
inline void loadScene(const uint8_t* data, size_t size, const std::string& baseDir) {
  io::ParseOptions po;
  po.limits = tinyLimits();
  std::string text(reinterpret_cast<const char*>(data), size);
  io::SceneDesc desc = io::parseRayString(text, "fuzz.ray", baseDir, po);
  scene::BuildOptions bo;
  bo.limits = tinyLimits();
  bo.threads = 1;
  std::unique_ptr<scene::Scene> s = scene::Scene::build(desc, bo);
  lights::ObjectLightOptions lo;
  lo.maxLights = tinyLimits().maxLights;
  lo.kind = (size & 1) ? lights::ObjectLightKind::Omni : lights::ObjectLightKind::Oriented;
  lo.placement = (size & 2) ? lights::Placement::Course : lights::Placement::Stratified;
  (void)lights::addObjectLights(*s, lo);
  if (desc.instantRadiosity) {
    const io::InstantRadiosityDesc& ir = *desc.instantRadiosity;
    lights::VplOptions v;
    v.maxVpls = tinyLimits().maxVpls;
    if (ir.vpls) v.count = std::min(*ir.vpls, 200);
    if (ir.bounces) v.bounces = std::min(*ir.bounces, 8);
    if (ir.normalize) v.normalize = *ir.normalize;
    if (ir.clamp) v.clamp = *ir.clamp;
    if (ir.seed) v.seed = *ir.seed;
    if (v.count > 0) (void)lights::addVpls(*s, v);
  }
}

// compare: the reference file's bytes, "%%TEST%%", the test file's (without the separator
// both are the same bytes). Both read with readImage; when the sizes agree, the metrics,
// their JSON and the relative-error heatmap as `lightcuts compare` computes them.
inline constexpr std::string_view kTestSeparator = "%%TEST%%";
inline void compareImages(const uint8_t* data, size_t size) {
  std::string_view all(reinterpret_cast<const char*>(data), size);
  size_t sep = all.find(kTestSeparator);
  std::string_view ref = all.substr(0, sep);
  std::string_view test = sep == std::string_view::npos ? ref : all.substr(sep + kTestSeparator.size());
  std::string refPath = writeScratch("ref", ref), testPath = writeScratch("test", test);
  const uint64_t maxPixels = tinyLimits().maxTexturePixels;
  io::Image a = io::readImage(refPath, false, maxPixels);
  io::Image b = io::readImage(testPath, false, maxPixels);
  double threshold = size > 0 ? double(data[0]) / 64.0 : 0.02;  // compare --threshold, 0 .. ~4
  io::ImageMetrics m = io::compareImages(a, b, threshold);
  (void)io::metricsToJson(m);
  (void)io::heatmap(io::relativeErrors(a, b), a.width, a.height, 0, 0.05f, "relative error");
}

}  // namespace lc::fuzz
