// Materials with their textures resolved. The Phong model of the course ray tracer:
//   I = ke + ka*Ia + sum_lights atten*shadow*(kd*max(N.L,0) + ks*max(R.V,0)^shininess)
//       + kr*reflected + kt*refracted
#pragma once

#include <memory>
#include <optional>

#include "core/math.h"
#include "scene/texture.h"

namespace lc::scene {

// A colour parameter: a constant, or a texture looked up at the hit's uv.
struct TexColor {
  Color value;
  std::shared_ptr<const Texture> texture;
  Color eval(const Vec2& uv) const { return texture ? texture->lookup(uv) : value; }
  bool isBlack() const { return !texture && lc::isBlack(value); }
};

struct TexScalar {
  float value = 0;
  std::shared_ptr<const Texture> texture;
  float eval(const Vec2& uv) const { return texture ? texture->lookupScalar(uv) : value; }
};

// An object light's emission (see io::LuminosityDesc for the parameters).
struct Luminosity {
  TexColor colour;  // per-light colour, sampled at each light's uv
  float intensity = 1;
  bool perArea = false;  // intensity per unit of world area (io::LuminosityDesc::perArea)
  float density = 1;
  float attenConstant = 0, attenLinear = 0, attenQuadratic = 1;
  SourceLoc loc;
};

struct Material {
  TexColor emissive, ambient, diffuse, specular, reflective, transmissive;
  TexScalar shininess, index;
  std::optional<Luminosity> luminosity;
  bool emissiveSet = false;
  std::string name;
};

// Material values at one point, as shading uses them.
struct ShadingMaterial {
  Color ke, ka, kd, ks, kr, kt;
  float shininess = 0;
  float ior = 1;
};

}  // namespace lc::scene
