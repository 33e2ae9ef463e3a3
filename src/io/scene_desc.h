// What a scene file says, as plain data: the output of the .ray parser and the OBJ
// loader, the input of scene::Scene. Nothing here knows about Embree or rendering.
// Every element keeps the source location it came from, so later stages (texture
// loading, light placement, limits) can report errors at the right line.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/enum_names.h"
#include "core/error.h"
#include "core/math.h"

namespace lc::io {

// A texture reference: map("file") in a .ray file, map_Kd in an MTL.
struct TextureRef {
  std::string path;  // resolved against the referring file's directory
  SourceLoc loc;     // where it was referred to (for "missing texture" errors)
  // true for colour maps (8-bit sRGB images), linearised when the output is display-encoded
  // (--tonemap srgb or filmic; scene::BuildOptions::linearizeSrgbTextures); false for scalar
  // maps (shininess, index), read as values/255.
  bool srgb = false;
};

// A colour that is either a constant or a texture lookup.
struct ColorParam {
  Color value{0, 0, 0};
  std::optional<TextureRef> map;
};

// A scalar that is either a constant or a texture lookup (the texture's mean channel).
struct ScalarParam {
  float value = 0;
  std::optional<TextureRef> map;
};

// `luminosity = { ... }` inside a material: makes the object an object light.
//   colour     (r,g,b) | map("tex") | texture   default (1,1,1)
//   intensity  total emitted power of the object (units of point_light colour), default 1
//   density    point lights per unit of world-space area, default 1
//   constant/linear/quadratic_attenuation_coeff  default 0, 0, 1
//   per_area   intensity is per unit of world-space area (default false): the object's total
//              is intensity x area. `emission = Le` (COMP4411) makes colour = Le, intensity 1/pi,
//              per_area true: an area A gets total intensity A x intensity.
struct LuminosityDesc {
  ColorParam colour{Color(1, 1, 1), std::nullopt};
  bool colourFromDiffuse = false;  // `colour = texture`: use the material's diffuse map
  float intensity = 1;
  bool perArea = false;
  float density = 1;
  float attenConstant = 0, attenLinear = 0, attenQuadratic = 1;
  SourceLoc loc;
};

// The Phong material of the course ray tracer. Every colour defaults to 0, shininess to
// 0 and index to 1. A material block starts as a copy of the current default material.
struct MaterialDesc {
  std::string name;  // "" when anonymous
  ColorParam emissive, ambient, diffuse, specular, reflective, transmissive;
  ScalarParam shininess{0, std::nullopt};
  ScalarParam index{1, std::nullopt};
  bool emissiveSet = false;  // the block (or its default) set `emissive` explicitly
  std::optional<LuminosityDesc> luminosity;
  SourceLoc loc;
};

// Camera. Defaults: at the origin looking down -z, up +y, vertical fov 2*atan(0.5)
// (an image plane of height 1 at distance 1), aspect from the image size.
struct CameraDesc {
  Vec3 position{0, 0, 0};
  Vec3 viewDir{0, 0, -1};
  Vec3 upDir{0, 1, 0};
  float fovDegrees = 53.130102f;
  std::optional<float> aspectRatio;  // width / height, when the scene sets it
  SourceLoc loc;
};

// Triangle mesh data in the mesh's local frame. Faces are already triangulated (fans).
struct MeshDesc {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Vec3> normals;          // empty, or one per point
  std::vector<Vec2> uvs;              // empty, or one per point
  std::vector<int> vertexMaterials;   // empty, or one material index per point
  std::vector<int> triangleMaterials; // empty, or one material index per triangle (OBJ)
  bool genNormals = false;            // compute smooth vertex normals
};

enum class ShapeKind { Sphere, Box, Square, Cylinder, Cone, Mesh };

// One primitive instance under its accumulated object-to-world transform.
struct ObjectDesc {
  ShapeKind kind = ShapeKind::Sphere;
  Mat4 transform = Mat4::identity();  // object-to-world
  int material = 0;                   // index into SceneDesc::materials
  std::string name;
  // cylinder / cone
  bool capped = true;
  float height = 1, bottomRadius = 1, topRadius = 0;
  // mesh: index into SceneDesc::meshes
  int mesh = -1;
  // Object lights: emit from both sides of the surface (area_light), not just along the
  // outward/winding normal.
  bool twoSidedEmission = false;
  SourceLoc loc;
};

enum class LightKind { Point, Directional, Spot };

// point_light / directional_light / spot_light. Attenuation is the course renderer's
// min(1, 1/(a + b d + c d^2)) with defaults a = 0, b = 0, c = 1.
struct LightDesc {
  LightKind kind = LightKind::Point;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, 0, -1};  // directional: the direction light travels; spot: the axis
  Color colour{1, 1, 1};
  float attenConstant = 0, attenLinear = 0, attenQuadratic = 1;
  // Spot falloff. The seed's form: max(0, cos angle)^exponent, zero beyond cutoff.
  // Public UW form: cone_angle/penumbra (degrees) with a smooth edge. size/blend
  // (Blender-like) maps onto cone_angle/penumbra.
  float exponent = 0;
  float cutoffDegrees = 90;
  std::optional<float> coneAngleDegrees;  // full cone half-angle, UW form
  float penumbraDegrees = 0;
  // spot_light `cutoff_distance` (UW form): no light beyond this distance from the light.
  float cutoffDistance = kInf;
  SourceLoc loc;
};

// How VPL intensities are normalised: instant_radiosity's `normalize`, --vpl-normalize,
// lights::VplOptions::normalize (applied in lights/vpl.cpp). Its one definition, with its
// names, here in the scene description: the parser, the CLI and the VPLs all read it.
enum class VplNormalize {
  Power,   // energy conserving: each path carries its light's power / number of paths (default)
  Object,  // the seed's: a VPL's intensity divided by the number of VPLs on its object
};
// Its names (core/enum_names.h), in the order the help and messages list them.
inline constexpr EnumName<VplNormalize> kVplNormalizeNames[] = {
    {VplNormalize::Power, "power", "energy conserving"},
    {VplNormalize::Object, "object", "the seed's per-object division"}};
inline const char* vplNormalizeName(VplNormalize v) { return enumName(kVplNormalizeNames, v); }
// Throws lc::Error for another name.
inline VplNormalize parseVplNormalize(std::string_view name) {
  return parseEnum(kVplNormalizeNames, name, "VPL normalisation");
}

// The model of a caustic light: instant_radiosity's `caustic_lights`, --caustic-lights,
// lights::CausticOptions::kind (lights/caustics.h, which holds the default and describes
// both models). Its one definition, here for the same reason as VplNormalize's.
enum class CausticLightKind { Vpl, Spot };
inline constexpr EnumName<CausticLightKind> kCausticLightKindNames[] = {
    {CausticLightKind::Vpl, "vpl", "an oriented light lifted off the hit, facing it"},
    {CausticLightKind::Spot, "spot", "the seed's: a spot at the last mirror or glass vertex"}};
inline const char* causticLightKindName(CausticLightKind k) { return enumName(kCausticLightKindNames, k); }
// Throws lc::Error for another name.
inline CausticLightKind parseCausticLightKind(std::string_view name) {
  return parseEnum(kCausticLightKindNames, name, "caustic light kind");
}

// instant_radiosity { vpls; bounces; normalize; clamp; seed; caustics; caustic_lights; }  (command line overrides)
struct InstantRadiosityDesc {
  std::optional<int> vpls;
  std::optional<int> bounces;
  std::optional<VplNormalize> normalize;
  std::optional<float> clamp;
  std::optional<uint64_t> seed;
  std::optional<int> caustics;                // light paths for caustic lights (lights/caustics.h)
  std::optional<CausticLightKind> causticLights;
  SourceLoc loc;
};

// environment_light { map; colour; intensity; up; rotate; lights; visible; } and
// sun_sky_light { direction; turbidity; intensity; lights; ground; visible; }: light from
// infinitely far away in every direction, turned into `lights` directional lights when the
// scene loads (lights/environment_lights.h). Radiance convention: a diffuse surface of
// albedo kd under a uniform environment of radiance L, unoccluded, renders as kd * L.
enum class EnvironmentKind { Map, SunSky };

struct EnvironmentDesc {
  EnvironmentKind kind = EnvironmentKind::Map;
  // environment_light: an equirectangular map (linear radiance; 8-bit images sRGB-decoded),
  // or none for a uniform environment of radiance colour * intensity.
  std::optional<TextureRef> map;
  Color colour{1, 1, 1};   // multiplies the map
  float intensity = 1;     // scale (both kinds)
  Vec3 up{0, 1, 0};        // the map's zenith
  float rotateDegrees = 0; // about up
  int lights = 4096;       // directional lights it becomes (--env-lights overrides)
  bool visible = true;     // seen by camera, reflected and refracted rays that miss everything
  // sun_sky_light (Preetham et al. 1999): the direction sunlight travels (y is up), the
  // atmosphere's turbidity, and the radiance below the horizon (a ground of that albedo).
  Vec3 sunDirection{0, -1, 0};
  float turbidity = 3;
  Color ground{0, 0, 0};
  SourceLoc loc;
};

struct SceneDesc {
  std::string path;  // the scene file
  CameraDesc camera;
  bool hasCamera = false;
  std::vector<MaterialDesc> materials;  // index 0 is the initial default material
  std::vector<MeshDesc> meshes;
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  Color ambient{0, 0, 0};  // sum of ambient_light colours
  std::optional<InstantRadiosityDesc> instantRadiosity;
  std::vector<EnvironmentDesc> environments;  // environment_light and sun_sky_light blocks
  std::vector<std::string> warnings;  // e.g. what --lenient skipped
};

}  // namespace lc::io
