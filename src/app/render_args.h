// The options of `lightcuts render` as parsed (render_command.cpp), shared with its report
// (summary.h). Each default is read from the options struct that owns it.
#pragma once

#include <cstdint>
#include <string>

#include "app/scene_loader.h"
#include "lightcuts/evaluator.h"
#include "render/renderer.h"

namespace lc::app {

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

}  // namespace lc::app
