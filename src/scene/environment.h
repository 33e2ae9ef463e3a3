// Light from infinitely far away: `environment_light` (an equirectangular radiance map, or a
// uniform colour) and `sun_sky_light` (Preetham et al. 1999's sky, plus the sun). An
// Environment answers what a ray that escapes the scene sees, and holds the table that
// lights/environment_lights.h turns into directional lights.
//
// Radiance convention (pbrt's): a diffuse surface of albedo kd under a uniform environment
// of radiance L, unoccluded, renders as kd * L. A directional light of intensity I adds
// kd * cos * I (src/lightcuts/shading.h), so a patch of environment of radiance L and solid
// angle w becomes a directional light of intensity L * w / pi.
//
// The map's frame: `up` is its zenith (the top row), reached from +y by the smallest
// rotation, then turned by `rotate` degrees about up (right-handed). With up = +y and no
// rotation the map's centre column looks toward -z, a quarter of the width to its right
// toward +x, the left and right edges toward +z.
#pragma once

#include <optional>
#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "core/math.h"
#include "io/image.h"
#include "io/scene_desc.h"
#include "scene/sky.h"

namespace lc::scene {

class Environment {
 public:
  // Loads the map (errors name the map's place in the scene file) or bakes the sky.
  static Environment build(const io::EnvironmentDesc& desc, const Limits& limits = {});

  // Radiance toward unit world direction d (the sun's disk included).
  Color radiance(const Vec3& d) const;
  // What a ray escaping toward d sees: radiance(d), or 0 when the environment is not visible.
  Color background(const Vec3& d) const { return visible_ ? radiance(d) : Color(0); }

  // The equirectangular table the directional lights are drawn from: radiance per pixel,
  // constant over each pixel's solid angle (a 1x1 table for a uniform environment). The
  // sun is not in it.
  const io::Image& table() const { return table_; }
  // Unit world direction at equirectangular coordinates (u, v) in [0,1]^2 (v = 0: the zenith).
  Vec3 direction(double u, double v) const;
  // Equirectangular coordinates of unit world direction d.
  void coordinates(const Vec3& d, double& u, double& v) const;

  // The sun of a sun_sky_light: the direction sunlight travels and its irradiance at normal
  // incidence (scaled to the scene's units), to become one directional light of intensity
  // irradiance / pi.
  bool hasSun() const { return hasSun_; }
  Vec3 sunTravel() const { return sunTravel_; }
  Color sunIrradiance() const { return sunIrradiance_; }

  io::EnvironmentKind kind() const { return kind_; }
  int lights() const { return lights_; }
  bool visible() const { return visible_; }
  const SourceLoc& loc() const { return loc_; }
  // "environment_light (map 'sky.hdr', 256x128)", for info and messages.
  std::string describe() const;

 private:
  io::EnvironmentKind kind_ = io::EnvironmentKind::Map;
  io::Image table_;
  Vec3 ex_{1, 0, 0}, ey_{0, 1, 0}, ez_{0, 0, 1};  // the map's frame in world space
  bool uniform_ = false;
  std::string mapPath_;
  std::optional<PreethamSky> sky_;
  float skyScale_ = 1;   // kcd/m^2 -> scene radiance
  Color ground_{0};      // sun_sky_light: radiance below the horizon
  bool hasSun_ = false;
  Vec3 sunTravel_{0, -1, 0};
  Color sunIrradiance_{0};
  int lights_ = 4096;
  bool visible_ = true;
  SourceLoc loc_;
};

}  // namespace lc::scene
