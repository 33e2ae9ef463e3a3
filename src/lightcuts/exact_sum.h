// The exact estimate of a small cluster: the unshadowed sum of its lights (a walk over them,
// no rays) times one visibility, where a representative's estimate is a 0-or-all sample
// (clusters across a surface's horizon, evaluator.cpp); the sum alone bounds such a
// cluster's error while the cut is refined.
#pragma once

#include <cstdint>

#include "lightcuts/eval_stats.h"
#include "lightcuts/light_tree.h"
#include "lightcuts/shading.h"
#include "core/light.h"

namespace lc::lightcuts {

// Clusters of at most this many lights that end in a cut without a first-order estimate
// and without a lower bound (across a surface's horizon, where the clamped cosine is not
// smooth, or outside a spot's cone) are estimated by their exact unshadowed sum times one
// visibility. The representative alone is a 0-or-everything sample there, and a tree's
// fixed representative errs the same way over a whole surface: the white furnace's error
// for environment clusters at the default --error; on a post's face beside lights above a
// lattice (accuracy_test's pergola) +2% of the face's light from clusters whose
// representative is in front and -0.7% from those whose representative is behind, 1.9% of
// the image's pixels over 2% (docs/LIGHTCUTS.md).
constexpr uint32_t kExactSumMaxLights = 64;

// A cluster's unshadowed sum at a point, and where its brightest light is.
struct ExactSum {
  Color sum;
  float brightest = 0, brightestDist = kInf;
  Vec3 brightestDir;
};

// The unshadowed sum of the lights under `node` at sp, in double, walked in a fixed order.
ExactSum unshadowedSum(const LightSet& lights, const LightTree& tree, NodeRef node, const ShadingPoint& sp);

// The sum times a visibility: 1 when `knownVisible` (the cluster's representative was found
// visible), else that of its brightest light, one shadow ray (none when nothing is lit).
Color withVisibility(const ExactSum& e, Visibility& vis, EvalStats& stats, bool knownVisible);

}  // namespace lc::lightcuts
