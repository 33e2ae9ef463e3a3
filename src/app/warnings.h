// Warnings and hints that explain a surprising result (docs/ERRORS.md, "Warnings"). Each is
// one line on stderr, "lightcuts: warning: ..." (or "lightcuts: hint: ..."), printed also
// under --quiet, as the parser's warnings are: -q silences progress and the summary only.
#pragma once

#include <cstdint>
#include <string>

#include "io/image.h"

namespace lc::app {

void printWarning(const std::string& message);  // "lightcuts: warning: MESSAGE"
void printHint(const std::string& message);     // "lightcuts: hint: MESSAGE"

// What is known after a render, for blackImageWarning.
struct RenderFacts {
  size_t lights = 0;            // point lights, object lights and VPLs
  uint64_t primaryRays = 0;     // camera rays
  uint64_t shadingPoints = 0;   // hits that were shaded (primary and secondary)
  uint64_t shadowRays = 0;
  uint64_t occludedRays = 0;    // shadow rays that found their light hidden (a lower bound)
  // The share of a grid of camera rays that hit any surface, black or not (-1: unknown):
  // few shading points with many hits means the surfaces' materials are black.
  double cameraHitFraction = -1;
};

// The fraction of pixels counted as black: those whose every channel is at most
// kBlackLevel out of 255 once tone-mapped for display (`tonemap`, 2^exposure).
constexpr int kBlackLevel = 2;
double blackFraction(const io::Image& image, io::ToneMap tonemap, float exposure);

// The warning for an image that is all or mostly (kMostlyBlack of its pixels) black, with the
// likeliest reason from `facts`; empty when the image is not mostly black.
constexpr double kMostlyBlack = 0.98;
std::string blackImageWarning(const io::Image& image, io::ToneMap tonemap, float exposure, const RenderFacts& facts);

// The warning for cuts that ran out of --max-cut nodes before their error bound held
// (EvalStats::cutsAtMaxCut): over kMaxCutShare of the shading points, their pixels may be
// further from brute force than --error. Empty otherwise.
constexpr double kMaxCutShare = 0.001;
std::string maxCutWarning(uint64_t cutsAtMaxCut, uint64_t shadingPoints, int maxCut);

// The hint for an error message: --lenient for unknown keywords; empty for other errors.
std::string hintForError(const std::string& bareMessage);

}  // namespace lc::app
