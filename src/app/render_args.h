// The options of `lightcuts render` as parsed (render_command.cpp), shared with its report
// (summary.h). Each default is read from the options struct that owns it; an option with
// named values holds its enum, parsed once on the command line (addEnumOption).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "app/scene_loader.h"
#include "io/image.h"
#include "lightcuts/evaluator.h"
#include "render/renderer.h"

namespace lc::app {

struct RenderArgs {
  std::string scene;
  std::string out;
  int width = 0, height = 0;
  int spp = render::RenderOptions{}.spp;
  render::AntiAliasing aa = render::RenderOptions{}.aa;
  int aaSamples = render::RenderOptions{}.aaSamples;
  bool aaExtrapolationProbe = render::RenderOptions{}.aaExtrapolationProbe;
  bool aaPixelSamples = render::RenderOptions{}.aaPixelSamples;
  bool reconstructRefine = render::RenderOptions{}.reconstructRefine;
  std::string aov;  // comma-separated kAovNames
  int threads = 0;
  int maxDepth = 5;
  std::string stats;
  bool quiet = false;
  lightcuts::Method method = lightcuts::Method::Lightcuts;
  std::optional<lightcuts::TreeBuilder> tree;  // default: by method
  float error = -1;  // default: by method
  int maxCut = lightcuts::CutOptions{}.maxCut;
  int stochasticCut = lightcuts::CutOptions{}.stochasticCut;
  lightcuts::CutCriterion criterion = lightcuts::CutOptions{}.criterion;
  lightcuts::Estimator estimator = lightcuts::CutOptions{}.estimator;
  bool visibilityProbes = lightcuts::CutOptions{}.visibilityProbes;
  bool clearClusters = lightcuts::CutOptions{}.clearClusters;
  bool secondSamples = lightcuts::CutOptions{}.secondSamples;
  std::string cutHeatmap;
  int referencePixels = 0;
  std::string errorFloor = "auto";
  std::string reconstruct = "auto";
  std::string reconstructCoarse = "auto";
  float reconstructSplit = render::RenderOptions{}.reconstructSplit;
  // 8-bit output is display-ready by default (writeImage's own default is Clamp).
  io::ToneMap tonemap = io::ToneMap::Srgb;
  float exposure = 0;  // EV: 8-bit outputs scale linear values by 2^exposure
  uint64_t seed = 1;
  LoadOptions load;
};

}  // namespace lc::app
