// Brute force at sampled pixels: the measured error of a render, and what a full
// brute-force image would cost, without rendering one (RenderOptions::referencePixels,
// ReferenceStats); and the VPL clamp's share of the light, measured the same way.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "lightcuts/evaluator.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace lc::render {

// K pixels spread over a w x h image (Halton 2,3), without duplicates.
std::vector<std::pair<int, int>> referencePixelSet(int k, int w, int h);

// The reference pixels of a finished render `res` (made with `evaluator` and `o`; under
// reconstruction cuts when `reconstructed`): brute force at o.referencePixels pixels, into
// res.stats.reference. A distributed render computes its share of the pixels here and
// the gathering process reports the error. A cancel marks the result interrupted.
void measureReference(const scene::Scene& scene, const lightcuts::LightEvaluator& evaluator, const RenderOptions& o,
                      bool reconstructed, RenderResult& res);

// Fraction of the VPLs' direct contribution that their distance clamp removes, measured
// exactly (with visibility) at primary hits of `points` pixels spread over the image, over
// every VPL or, where points x VPLs would exceed `maxEvaluations`, an evenly strided subset
// of them at each point. 0 when the scene has no VPLs.
double vplClampedFraction(const scene::Scene& scene, const RenderOptions& options, int points = 256,
                          uint64_t maxEvaluations = 4'000'000);

}  // namespace lc::render
