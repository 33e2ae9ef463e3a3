// Caustics as many lights (issue 25): light focused by mirrors and glass, rendered by the
// same light tree and cuts as every other light.
//
// Light paths leave the scene's lights (in proportion to power, every kind, through
// lights::EmissionSampler) and follow specular reflection and refraction with the
// materials' kr, kt and index: the weights and directions camera rays use (no Fresnel
// term: the renderer has none). Where a path that has been through at least one specular
// bounce reaches a surface with a diffuse colour, it leaves a caustic light carrying the
// path's flux Phi (before the receiver's kd: the receiver multiplies its own kd, so
// textures stay sharp). Two models (CausticLightKind):
//
//   vpl  an oriented light lifted a smoothing height h off the hit along the
//        normal, facing the surface: on a plane it lights I h^2 / (h^2 + rho^2)^2 at
//        distance rho, whose integral is pi I, so I = Phi / pi gives back exactly Phi
//        (a splat of the photon, the density estimate done by the lights themselves);
//   spot (default) the seed's idea: a spot light at the last specular vertex, aimed along the path,
//        with falloff cos^e; e = 1 / sigma^2 for an angular spread sigma, quantised to a
//        power of two (one LightGroup per exponent), I = Phi (e + 1) / (2 pi).
//
// Both take their size from the spread of neighbouring paths: R = smoothing x the distance
// from the hit to its k-th nearest other hit (k = neighbours); the half of each light's
// light falls within R of its hit (vpl: h = R; spot: sigma = R / (1.177 D) over the
// distance D from the last specular vertex).
//
// Counting light once: with caustics on, addCaustics turns the scene's shadows through glass
// off (Scene::setShadowsThroughGlass(false)), so light that reaches a point through a
// transmissive surface is carried only by the caustic lights, never also by a kt-weighted
// shadow ray. (Mirrors were opaque to shadow rays already.)
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/progress.h"
#include "io/scene_desc.h"
#include "scene/scene.h"

namespace lc::lights {

// The values, their names and their parsing: io/scene_desc.h (the scene's
// instant_radiosity block and --caustic-lights share them).
using io::CausticLightKind;

struct CausticOptions {
  int paths = 0;  // --caustics: light paths shot (most miss the specular objects)
  // The default measured better (docs/LIGHTCUTS.md, "Caustics"): on the ball lens and the
  // mirror ring, as accurate against photon splatting and 1.4-6x faster to render.
  CausticLightKind kind = CausticLightKind::Spot;
  int maxSpecularBounces = 10;
  int neighbours = 16;     // k of the k-th nearest hit that sizes each light
  float smoothing = 1.0f;  // R = smoothing x that distance
  uint64_t seed = 1;
  uint64_t maxLights = 10'000'000;
  ProgressFn progress = {};
  const std::atomic<bool>* cancel = nullptr;  // as VplOptions::cancel
};

struct CausticInfo {
  uint64_t paths = 0;
  uint64_t lights = 0;
  double seconds = 0;
  Color power;           // the flux the caustic lights carry (sum of Phi)
  float meanRadius = 0;  // mean R, world units
  CausticLightKind kind = CausticLightKind::Vpl;
};

// Where a caustic path reaches a diffuse surface.
struct CausticHit {
  Vec3 position;
  Vec3 normal;  // shading normal, on the side the light arrives from
  Vec3 from;    // the last specular vertex (just off its surface)
  Color flux;   // the flux arriving, before the surface's kd
  int shape = -1;
};

// The lights caustic paths start from: every light but VPLs.
std::vector<Light> causticSources(const LightSet& set);

// Paths [0, paths) of `paths` with their own random streams (path p from (seed, p)), in
// path order whatever the thread count.
std::vector<CausticHit> traceCausticPaths(const scene::Scene& scene, const std::vector<Light>& sources, size_t paths,
                                          uint64_t seed, int maxSpecularBounces, const ProgressFn& progress = {},
                                          const std::atomic<bool>* cancel = nullptr);

// Appends caustic lights to scene.lights() (sources: causticSources, so call it after the
// VPLs) and turns off shadows through glass when options.paths > 0. Throws lc::Error for bad
// options or limits, lc::Interrupted when cancelled.
CausticInfo addCaustics(scene::Scene& scene, const CausticOptions& options);

// The brute-force reference (photon splatting): the irradiance at each point (with its
// normal) from the hits within `radius` on the same side of a surface, flux / (pi r^2).
// Converges to the caustic's irradiance as the paths grow and the radius shrinks; a
// diffuse point shows kd times it.
std::vector<Color> causticIrradiance(const std::vector<CausticHit>& hits, const std::vector<Vec3>& points,
                                     const std::vector<Vec3>& normals, float radius);

}  // namespace lc::lights
