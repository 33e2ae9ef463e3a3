// Environment and sky light as directional lights (issue 24). Each environment_light or
// sun_sky_light of the scene (scene/environment.h) becomes `lights` directional lights drawn
// from its equirectangular table with density proportional to luminance x solid angle, on a
// stratified point set (the first N points of Sobol's (0,2)-sequence, Owen-scrambled by the
// seed, through the table's marginal/conditional inversion: monotone in both coordinates,
// so the strata stay strata). With S the sum over pixels of luminance Y x solid angle, a light drawn in pixel p
// of radiance L_p stands for the solid angle S / (N Y_p) and gets the intensity
// L_p S / (N Y_p pi): every drawn light has the same luminance S / (N pi), one share. A
// sun_sky_light's sun is one more light of intensity (its irradiance) / pi.
// A pixel smaller than 4 pi / 4,096 sr (whatever N) is whole: the lights drawn in it are
// merged into one (summed intensity, mean direction), and one worth 8 shares or more (a
// map's one-pixel sun) is one light of its exact power at its centroid, taking
// floor(power / share) of the N lights, and the rest of the map is drawn with the others. So
// `lights` is an upper bound on the count, and a pixel is treated alike at every N (the
// lights converge to the map as N grows: docs/BENCHMARKS.md).
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "scene/scene.h"

namespace lc::lights {

struct EnvironmentLightOptions {
  std::optional<int> count;  // --env-lights: overrides every block's `lights`
  uint64_t seed = 1;         // --seed: scrambles the point set
  uint64_t maxLights = 20'000'000;
  ProgressFn progress = {};  // the share of lights made (core/progress.h)
  const std::atomic<bool>* cancel = nullptr;  // stops and throws lc::Interrupted
};

struct EnvironmentLightInfo {
  std::string what;  // Environment::describe()
  uint64_t lights = 0;     // directional lights added (the sun's included)
  Color power;             // sum of the lights' intensities x pi: the irradiance of a
                           // surface facing every light at once, a check of the total
};

// Draws `count` directions from an environment's table (at most `count` lights after
// merging): unit directions toward the light (not the travel direction) and intensities,
// as described above. Exposed for tests.
void sampleEnvironment(const scene::Environment& env, int count, uint64_t seed, std::vector<Vec3>& toLight,
                       std::vector<Color>& intensity, Progress* progress = nullptr);

// Appends every environment's directional lights to scene.lights().
std::vector<EnvironmentLightInfo> addEnvironmentLights(scene::Scene& scene, const EnvironmentLightOptions& options);

}  // namespace lc::lights
