// The renderable scene: world-space geometry in an Embree BVH, resolved materials and
// textures, the camera and the light list. Built once from an io::SceneDesc; immutable
// and thread-safe for queries afterwards (the light list can still be extended by the
// object-light and VPL generators before rendering starts).
#pragma once

#include <embree3/rtcore.h>

#include <memory>
#include <string>
#include <vector>

#include "core/limits.h"
#include "core/progress.h"
#include "io/scene_desc.h"
#include "scene/camera.h"
#include "scene/environment.h"
#include "core/light.h"
#include "scene/material.h"
#include "scene/occluders.h"
#include "scene/planar_faces.h"
#include "scene/shape.h"

namespace lc::scene {

struct Ray {
  Vec3 o, d;  // d need not be unit length; t is in units of |d|
  float tmin = 0, tmax = kInf;
};

// A ray-surface intersection with everything shading needs.
struct Hit {
  float t = kInf;
  Vec3 p;        // world position
  Vec3 ng;       // unit geometric normal, facing the incoming ray
  Vec3 ns;       // unit shading normal, on the same side as ng
  Vec2 uv;       // texture coordinates
  bool frontFace = true;  // the ray hit the outside (the side the stored normal points to)
  int shape = -1;         // index into Scene::shapes()
  int prim = 0;           // triangle index for meshes
  Vec3 bary;              // barycentrics (meshes)
};

struct BuildOptions {
  Limits limits;
  int threads = 0;  // 0 = all cores
  // Decode textures marked TextureRef::srgb (MTL colour maps) to linear values. Off, every
  // 8-bit texture reads as value/255, as the course renderer did; the CLI turns it on with
  // --tonemap srgb, whose output encoding undoes the linearisation.
  bool linearizeSrgbTextures = false;
  // Build the occluder index (occluders.h) that lightcuts' clear clusters query; without
  // it no cluster is known clear. About 24 bytes per triangle; the CLI leaves it out
  // where nothing will query it (brute force, --clear-clusters off).
  bool occluders = true;
  // Split the meshes into flat convex faces (planar_faces.h), which lightcuts' visibility
  // probes ask whether they hide a cluster. About 4 bytes per triangle and 100 per face;
  // the CLI leaves them out where nothing will ask (brute force, --visibility-probes off).
  bool planarFaces = true;
  // Told how far the build is (core/progress.h): meshes, Embree's hierarchy, the occluder
  // index and the planar faces (a 2M-triangle mesh takes over a second).
  ProgressFn progress = {};
};

class Scene {
 public:
  // Builds geometry, materials (textures loaded and shared) and the scene's own lights.
  // Throws lc::Error on bad input (singular transforms, missing textures, limits).
  static std::unique_ptr<Scene> build(const io::SceneDesc& desc, const BuildOptions& options = {});
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // Closest hit along the ray within [tmin, tmax].
  bool intersect(const Ray& ray, Hit& hit) const;
  // Fraction of light that reaches along the segment origin + t*dir, t in (0, tmax):
  // 0 behind an opaque surface, the product of transmissive colours through glass.
  Color transmittance(const Vec3& origin, const Vec3& dir, float tmax) const;
  // Binary visibility, the fast path for scenes without transmissive materials.
  bool occluded(const Vec3& origin, const Vec3& dir, float tmax) const;
  // The nearest surface along the segment: its shape index and distance, or -1.
  // `prim`, when given, receives the triangle's index within a mesh (0 for quadrics).
  int firstHit(const Vec3& origin, const Vec3& dir, float tmax, float& t, int* prim = nullptr) const;
  bool hasTransmissive() const { return hasTransmissive_; }
  // Off, shadow rays treat transmissive surfaces as opaque (transmittance() is 0 or 1 and
  // isTransmissive() is false): with caustics on, the light that passes glass is carried by
  // the caustic lights alone (lights/caustics.h), not also by shadow rays. Default on.
  void setShadowsThroughGlass(bool on) { shadowsThroughGlass_ = on; }
  bool shadowsThroughGlass() const { return shadowsThroughGlass_; }
  // Whether a shape is a convex solid or a flat convex polygon: one that blocks a set of
  // directions from a point blocks their convex hull too.
  bool isConvex(int shape) const { return convex_[size_t(shape)] != 0; }
  // World bounds of a convex shape (isConvex; empty for the others): a ray that meets the
  // shape meets its box.
  const Bounds3& convexBounds(int shape) const { return convexBounds_[size_t(shape)]; }
  // Whether light can pass through some part of a shape (a transmissive material).
  bool isTransmissive(int shape) const { return shadowsThroughGlass_ && transmissive_[size_t(shape)] != 0; }
  // Every surface as convex pieces, for proving a set of segments clear (occluders.h).
  const OccluderIndex& occluders() const { return occluders_; }
  // The meshes' flat convex faces (empty unless BuildOptions::planarFaces).
  const PlanarFaces& planarFaces() const { return planarFaces_; }

  // Material values at a hit (textures looked up, per-vertex materials blended).
  ShadingMaterial shadingMaterial(const Hit& hit) const;

  // A point slightly off the surface on the side `dir` points to and slightly along `dir`,
  // for secondary rays.
  Vec3 offsetOrigin(const Hit& hit, const Vec3& dir) const;
  float epsilon() const { return epsilon_; }

  const Camera& camera() const { return camera_; }
  void setCamera(const Camera& c) { camera_ = c; }
  const std::vector<Shape>& shapes() const { return shapes_; }
  const std::vector<Mesh>& meshes() const { return meshes_; }
  const std::vector<Material>& materials() const { return materials_; }
  const Material& materialOf(const Hit& hit) const;
  const Bounds3& bounds() const { return bounds_; }
  Color ambient() const { return ambient_; }
  // environment_light and sun_sky_light blocks (their directional lights are added by
  // lights::addEnvironmentLights).
  const std::vector<Environment>& environments() const { return environments_; }
  // What a ray that escapes toward unit direction d sees: the sum of the visible
  // environments (0 without any).
  Color background(const Vec3& d) const {
    Color c(0);
    for (const Environment& e : environments_) c += e.background(d);
    return c;
  }
  LightSet& lights() { return lights_; }
  const LightSet& lights() const { return lights_; }
  // The camera as the scene file described it (the image's aspect ratio is the caller's).
  const io::CameraDesc& cameraDesc() const { return cameraDesc_; }
  size_t triangleCount() const;

 private:
  Scene() = default;
  void buildGeometry(const BuildOptions& options);

  io::CameraDesc cameraDesc_;
  Camera camera_;
  std::vector<Material> materials_;
  std::vector<Shape> shapes_;
  std::vector<Mesh> meshes_;
  LightSet lights_;
  std::vector<Environment> environments_;
  Color ambient_;
  Bounds3 bounds_;
  float epsilon_ = 1e-4f;
  bool hasTransmissive_ = false;
  bool shadowsThroughGlass_ = true;
  std::vector<uint8_t> convex_;        // per shape
  std::vector<Bounds3> convexBounds_;  // per shape: its world bounds if convex, else empty
  std::vector<uint8_t> transmissive_;  // per shape
  OccluderIndex occluders_;
  PlanarFaces planarFaces_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_ = nullptr;
};

}  // namespace lc::scene
