#include "scene/scene.h"

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <mutex>

#include "scene/texture.h"

namespace lc::scene {

namespace {

using io::ShapeKind;

// ---- Embree user geometry for the analytic quadrics -------------------------------

void quadricBoundsFunc(const RTCBoundsFunctionArguments* args) {
  const Shape* s = static_cast<const Shape*>(args->geometryUserPtr);
  RTCBounds* b = args->bounds_o;
  b->lower_x = s->bounds.lo.x; b->lower_y = s->bounds.lo.y; b->lower_z = s->bounds.lo.z;
  b->upper_x = s->bounds.hi.x; b->upper_y = s->bounds.hi.y; b->upper_z = s->bounds.hi.z;
}

// The ray is transformed to the canonical frame (origin o, direction d); t is the same in
// both frames.
bool hitQuadricLocal(const Shape& s, const RTCRay& r, float& t, int& part, Vec3& o, Vec3& d) {
  o = s.toLocal.point(Vec3(r.org_x, r.org_y, r.org_z));
  d = s.toLocal.vector(Vec3(r.dir_x, r.dir_y, r.dir_z));
  return intersectQuadric(s, o, d, r.tnear, r.tfar, t, part);
}

bool hitQuadric(const Shape& s, const RTCRay& r, float& t, int& part, Vec3& worldNormal) {
  Vec3 o, d;
  if (!hitQuadricLocal(s, r, t, part, o, d)) return false;
  Vec3 pl = o + d * t;
  worldNormal = s.toLocal.normalFromInverse(quadricLocalNormal(s, pl, part));
  return true;
}

void quadricIntersectFunc(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const Shape* s = static_cast<const Shape*>(args->geometryUserPtr);
  RTCRayHit* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);  // N == 1 for rtcIntersect1
  float t;
  int part;
  Vec3 n;
  if (!hitQuadric(*s, rh->ray, t, part, n)) return;
  rh->ray.tfar = t;
  rh->hit.Ng_x = n.x; rh->hit.Ng_y = n.y; rh->hit.Ng_z = n.z;
  rh->hit.u = float(part);
  rh->hit.v = 0;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
}

void quadricOccludedFunc(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const Shape* s = static_cast<const Shape*>(args->geometryUserPtr);
  RTCRay* r = reinterpret_cast<RTCRay*>(args->ray);
  // Whether it is hit, no more: a shadow ray needs no normal (its transform and the local
  // normal were a third of the callback, perf on the warehouse of boxes).
  float t;
  int part;
  Vec3 o, d;
  if (hitQuadricLocal(*s, *r, t, part, o, d)) r->tfar = -kInf;
}

void embreeErrorFunc(void*, RTCError code, const char* str) {
  fmt::print(stderr, "embree error {}: {}\n", int(code), str ? str : "");
}

// A texture through the cache; an sRGB-marked map is linearised only when the options ask.
std::shared_ptr<const Texture> resolveTexture(const io::TextureRef& ref, TextureCache& cache,
                                              const BuildOptions& options) {
  io::TextureRef r = ref;
  r.srgb = ref.srgb && options.linearizeSrgbTextures;
  return cache.get(r, options.limits);
}

TexColor resolveColor(const io::ColorParam& p, TextureCache& cache, const BuildOptions& options) {
  TexColor c;
  c.value = p.value;
  if (p.map) c.texture = resolveTexture(*p.map, cache, options);
  return c;
}

TexScalar resolveScalar(const io::ScalarParam& p, TextureCache& cache, const BuildOptions& options) {
  TexScalar s;
  s.value = p.value;
  if (p.map) s.texture = resolveTexture(*p.map, cache, options);
  return s;
}

// Embree asserts (RTCRay::valid) that origin and direction lie within +-1.844e18 and that
// tnear/tfar are not NaN. Rays that fail this (from huge or non-finite geometry, or a
// degenerate refraction) are not traced: they hit nothing and light is treated as blocked.
bool rayIsValid(const Vec3& o, const Vec3& d, float tnear, float tfar) {
  constexpr float kLarge = 1.8e18f;
  auto ok = [&](float x) { return std::fabs(x) <= kLarge; };  // false for NaN and inf
  return ok(o.x) && ok(o.y) && ok(o.z) && ok(d.x) && ok(d.y) && ok(d.z) && tnear >= 0 &&
         !std::isnan(tfar);
}

// A closest-hit query from o along d over [tnear, tfar], no hit yet.
RTCRayHit rayHit(const Vec3& o, const Vec3& d, float tnear, float tfar) {
  RTCRayHit rh;
  rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

}  // namespace

Scene::~Scene() {
  if (rtc_) rtcReleaseScene(rtc_);
  if (device_) rtcReleaseDevice(device_);
}

std::unique_ptr<Scene> Scene::build(const io::SceneDesc& desc, const BuildOptions& options) {
  std::unique_ptr<Scene> scene(new Scene());
  Scene& s = *scene;
  s.cameraDesc_ = desc.camera;
  s.ambient_ = desc.ambient;

  // Materials, with every texture decoded once and shared.
  TextureCache cache;
  for (const io::MaterialDesc& md : desc.materials) {
    Material m;
    m.name = md.name;
    m.emissive = resolveColor(md.emissive, cache, options);
    m.ambient = resolveColor(md.ambient, cache, options);
    m.diffuse = resolveColor(md.diffuse, cache, options);
    m.specular = resolveColor(md.specular, cache, options);
    m.reflective = resolveColor(md.reflective, cache, options);
    m.transmissive = resolveColor(md.transmissive, cache, options);
    m.shininess = resolveScalar(md.shininess, cache, options);
    m.index = resolveScalar(md.index, cache, options);
    m.emissiveSet = md.emissiveSet;
    if (md.luminosity) {
      const io::LuminosityDesc& ld = *md.luminosity;
      Luminosity l;
      l.colour = ld.colourFromDiffuse ? m.diffuse : resolveColor(ld.colour, cache, options);
      l.intensity = ld.intensity;
      l.perArea = ld.perArea;
      l.density = ld.density;
      l.attenConstant = ld.attenConstant;
      l.attenLinear = ld.attenLinear;
      l.attenQuadratic = ld.attenQuadratic;
      l.loc = ld.loc;
      m.luminosity = l;
    }
    if (!m.transmissive.isBlack()) s.hasTransmissive_ = true;
    s.materials_.push_back(std::move(m));
  }
  if (s.materials_.empty()) s.materials_.emplace_back();

  // Shapes: quadrics keep their transform; meshes are baked into world space.
  for (const io::ObjectDesc& od : desc.objects) {
    Shape sh;
    sh.kind = od.kind;
    sh.toWorld = od.transform;
    sh.material = (od.material >= 0 && size_t(od.material) < s.materials_.size()) ? od.material : 0;
    sh.capped = od.capped;
    sh.height = od.height;
    sh.bottomRadius = od.bottomRadius;
    sh.topRadius = od.topRadius;
    sh.name = od.name;
    sh.twoSidedEmission = od.twoSidedEmission;
    sh.loc = od.loc;
    if (!od.transform.isFinite() || !od.transform.inverseAffine(sh.toLocal))
      throw Error(od.loc, "the object's transform is singular or not finite (a zero scale?)");
    if (od.kind == ShapeKind::Mesh) {
      if (od.mesh < 0 || size_t(od.mesh) >= desc.meshes.size())
        throw Error(od.loc, "internal: mesh index out of range");
      const io::MeshDesc& md = desc.meshes[size_t(od.mesh)];
      Mesh mesh;
      mesh.positions.reserve(md.points.size());
      for (const Vec3& p : md.points) {
        Vec3 w = od.transform.point(p);
        if (!isFinite(w)) throw Error(od.loc, "a mesh vertex is not finite after its transform");
        mesh.positions.push_back(w);
        sh.bounds.extend(w);
      }
      mesh.triangles = md.triangles;
      for (const auto& t : mesh.triangles)
        for (int i : t)
          if (i < 0 || size_t(i) >= mesh.positions.size())
            throw Error(od.loc, fmt::format("face index {} out of range (the mesh has {} points)",
                                            i, mesh.positions.size()));
      if (md.genNormals || (!md.normals.empty() && md.normals.size() == md.points.size())) {
        mesh.normals.assign(md.points.size(), Vec3(0, 0, 0));
        if (md.genNormals) {
          // Area-weighted average of the face normals around each vertex.
          for (const auto& t : mesh.triangles) {
            Vec3 n = cross(mesh.positions[size_t(t[1])] - mesh.positions[size_t(t[0])],
                           mesh.positions[size_t(t[2])] - mesh.positions[size_t(t[0])]);
            for (int i : t) mesh.normals[size_t(i)] += n;
          }
        } else {
          for (size_t i = 0; i < md.normals.size(); ++i)
            mesh.normals[i] = sh.toLocal.normalFromInverse(md.normals[i]);
        }
        for (Vec3& n : mesh.normals) n = normalize(n);
      }
      if (md.uvs.size() == md.points.size()) mesh.uvs = md.uvs;
      mesh.vertexMaterials = md.vertexMaterials;
      mesh.triangleMaterials = md.triangleMaterials;
      for (int& mi : mesh.vertexMaterials)
        if (mi < 0 || size_t(mi) >= s.materials_.size()) mi = sh.material;
      for (int& mi : mesh.triangleMaterials)
        if (mi < 0 || size_t(mi) >= s.materials_.size()) mi = sh.material;
      sh.mesh = int(s.meshes_.size());
      s.meshes_.push_back(std::move(mesh));
    } else {
      sh.bounds = quadricBounds(sh);
    }
    if (!sh.bounds.empty()) s.bounds_.extend(sh.bounds);
    s.shapes_.push_back(std::move(sh));
  }

  // A scale-aware offset for secondary rays: large enough to clear float rounding at the
  // scene's coordinates, small against any feature.
  float scale = 1;
  if (!s.bounds_.empty()) scale = std::max(1.0f, maxComponent(vmax(vabs(s.bounds_.lo), vabs(s.bounds_.hi))));
  s.epsilon_ = 1e-4f * scale;

  // The scene's own lights.
  for (const io::LightDesc& ld : desc.lights) {
    Light l;
    l.intensity = ld.colour;
    l.position = ld.position;
    LightGroup g;
    g.atten = Attenuation{ld.attenConstant, ld.attenLinear, ld.attenQuadratic, kInf};
    switch (ld.kind) {
      case io::LightKind::Point:
        l.type = LightType::Omni;
        break;
      case io::LightKind::Directional:
        l.type = LightType::Directional;
        l.direction = normalizeScaled(ld.direction);
        g.atten = Attenuation{0, 0, 0, kInf};
        break;
      case io::LightKind::Spot: {
        l.type = LightType::Spot;
        l.direction = normalizeScaled(ld.direction);
        g.falloff.exponent = ld.exponent;
        g.falloff.cosCutoff = std::cos(std::clamp(ld.cutoffDegrees, 0.0f, 180.0f) * kPi / 180);
        if (ld.cutoffDegrees >= 180) g.falloff.cosCutoff = -1.0f - 1e-6f;
        if (ld.coneAngleDegrees) {
          float outer = std::clamp(*ld.coneAngleDegrees, 0.0f, 180.0f);
          float inner = std::clamp(outer - ld.penumbraDegrees, 0.0f, outer);
          g.falloff.cosOuter = std::cos(outer * kPi / 180);
          g.falloff.cosInner = std::cos(inner * kPi / 180);
          if (g.falloff.cosInner <= g.falloff.cosOuter) g.falloff.cosInner = g.falloff.cosOuter + 1e-6f;
        }
        break;
      }
    }
    if (ld.kind != io::LightKind::Directional) g.atten.maxDistance = ld.cutoffDistance;
    if (!isFinite(l.position) || !isFinite(l.intensity) || !isFinite(l.direction))
      throw Error(ld.loc, "light parameters must be finite");
    if (isBlack(l.intensity)) continue;
    if (!s.lights_.hasRoomFor(g))
      throw Error(ld.loc, "more than 65535 distinct light groups (attenuations, spot cones) in the scene");
    l.group = s.lights_.groupFor(g);
    s.lights_.lights.push_back(l);
  }

  for (const io::EnvironmentDesc& ed : desc.environments)
    s.environments_.push_back(Environment::build(ed, options.limits));

  float aspect = desc.camera.aspectRatio ? *desc.camera.aspectRatio : 1.0f;
  s.camera_ = Camera::fromDesc(desc.camera, aspect);
  s.buildGeometry(options);
  return scene;
}

// Shares of the geometry's build in its progress (measured on a 2M-triangle mesh: Embree's
// hierarchy and the occluder index take most of it; the rest is the planar faces').
constexpr double kGeometryShare = 0.1, kEmbreeShare = 0.4, kOccluderShare = 0.35;

void Scene::buildGeometry(const BuildOptions& options) {
  Progress progress(options.progress, 1.0);
  std::string config = options.threads > 0 ? fmt::format("threads={}", options.threads) : "";
  device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
  if (!device_) throw Error("cannot create the Embree device");
  rtcSetDeviceErrorFunction(device_, embreeErrorFunc, nullptr);
  rtc_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtc_, RTC_BUILD_QUALITY_HIGH);
  // Watertight triangle tests (issue 29): in the default mode a ray through an edge shared
  // by two triangles can miss both, which showed as black pixels along the diagonals of
  // quads seen head-on and would let shadow rays through closed meshes.
  rtcSetSceneFlags(rtc_, RTC_SCENE_FLAG_ROBUST);
  convex_.resize(shapes_.size());
  convexBounds_.assign(shapes_.size(), Bounds3());
  transmissive_.resize(shapes_.size());
  for (size_t i = 0; i < shapes_.size(); ++i) {
    Shape& sh = shapes_[i];
    const Mesh* mesh = sh.kind == ShapeKind::Mesh ? &meshes_[size_t(sh.mesh)] : nullptr;
    convex_[i] = isConvexShape(sh, mesh);
    if (convex_[i]) {
      if (mesh) {
        for (const auto& t : mesh->triangles)
          for (int k : t) convexBounds_[i].extend(mesh->positions[size_t(k)]);
      } else {
        convexBounds_[i] = quadricBounds(sh);
      }
    }
    bool glass = !materials_[size_t(sh.material)].transmissive.isBlack();
    if (mesh) {
      for (int m : mesh->triangleMaterials) glass |= !materials_[size_t(m)].transmissive.isBlack();
      for (int m : mesh->vertexMaterials) glass |= !materials_[size_t(m)].transmissive.isBlack();
    }
    transmissive_[i] = glass;
    RTCGeometry g;
    if (sh.kind == ShapeKind::Mesh) {
      const Mesh& m = meshes_[size_t(sh.mesh)];
      g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      // Embree reads vertex buffers 16 bytes at a time: let it allocate (and pad) them.
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
      for (size_t k = 0; k < m.positions.size(); ++k) {
        v[3 * k] = m.positions[k].x;
        v[3 * k + 1] = m.positions[k].y;
        v[3 * k + 2] = m.positions[k].z;
      }
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangles.size()));
      for (size_t k = 0; k < m.triangles.size(); ++k)
        for (int j = 0; j < 3; ++j) idx[3 * k + size_t(j)] = unsigned(m.triangles[k][size_t(j)]);
    } else {
      g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(g, 1);
      rtcSetGeometryUserData(g, &sh);
      rtcSetGeometryBoundsFunction(g, quadricBoundsFunc, nullptr);
      rtcSetGeometryIntersectFunction(g, quadricIntersectFunc);
      rtcSetGeometryOccludedFunction(g, quadricOccludedFunc);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(rtc_, g, unsigned(i));
    rtcReleaseGeometry(g);
  }
  progress.add(kGeometryShare);
  // Embree reports its build as a fraction done (from its worker threads; a fraction may
  // come twice or out of order, so only its growth is counted).
  struct Monitor {
    Progress* progress;
    std::atomic<double> seen{0};
  } monitor{&progress};
  rtcSetSceneProgressMonitorFunction(
      rtc_,
      [](void* ptr, double f) {
        auto* m = static_cast<Monitor*>(ptr);
        double before = m->seen.load(std::memory_order_relaxed);
        while (f > before && !m->seen.compare_exchange_weak(before, f, std::memory_order_relaxed)) {
        }
        if (f > before) m->progress->add(kEmbreeShare * (f - before));
        return true;  // never cancelled
      },
      &monitor);
  rtcCommitScene(rtc_);
  rtcSetSceneProgressMonitorFunction(rtc_, nullptr, nullptr);
  RTCError err = rtcGetDeviceError(device_);
  if (err != RTC_ERROR_NONE) throw Error(fmt::format("Embree failed to build the scene (error {})", int(err)));
  if (options.occluders) occluders_ = OccluderIndex(shapes_, meshes_);
  progress.add(kOccluderShare);
  if (options.planarFaces) planarFaces_ = PlanarFaces(shapes_, meshes_);
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const Mesh& m : meshes_) n += m.triangles.size();
  return n;
}

bool Scene::intersect(const Ray& ray, Hit& hit) const {
  RTCIntersectContext ctx;
  if (!rayIsValid(ray.o, ray.d, ray.tmin, ray.tmax)) return false;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = rayHit(ray.o, ray.d, ray.tmin, ray.tmax);
  rtcIntersect1(rtc_, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  const Shape& sh = shapes_[rh.hit.geomID];
  hit.t = rh.ray.tfar;
  hit.shape = int(rh.hit.geomID);
  hit.prim = int(rh.hit.primID);
  if (sh.kind == ShapeKind::Mesh) {
    const Mesh& m = meshes_[size_t(sh.mesh)];
    const auto& tri = m.triangles[rh.hit.primID];
    float u = rh.hit.u, v = rh.hit.v, w = 1 - u - v;
    hit.bary = Vec3(w, u, v);
    const Vec3& p0 = m.positions[size_t(tri[0])];
    const Vec3& p1 = m.positions[size_t(tri[1])];
    const Vec3& p2 = m.positions[size_t(tri[2])];
    hit.p = p0 * w + p1 * u + p2 * v;
    hit.ng = normalize(cross(p1 - p0, p2 - p0));
    if (!m.normals.empty()) {
      hit.ns = normalize(m.normals[size_t(tri[0])] * w + m.normals[size_t(tri[1])] * u +
                         m.normals[size_t(tri[2])] * v);
      if (!isFinite(hit.ns) || length2(hit.ns) == 0) hit.ns = hit.ng;
    } else {
      hit.ns = hit.ng;
    }
    if (!m.uvs.empty())
      hit.uv = m.uvs[size_t(tri[0])] * w + m.uvs[size_t(tri[1])] * u + m.uvs[size_t(tri[2])] * v;
    else
      hit.uv = Vec2(u, v);
  } else {
    hit.p = ray.o + ray.d * hit.t;
    hit.ng = normalize(Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    hit.ns = hit.ng;
    int part = int(rh.hit.u);
    hit.uv = quadricUv(sh, sh.toLocal.point(hit.p), part);
    hit.bary = Vec3(1, 0, 0);
  }
  // Normals face the incoming ray; frontFace remembers which side was hit (refraction).
  hit.frontFace = dot(hit.ng, ray.d) < 0;
  if (!hit.frontFace) {
    hit.ng = -hit.ng;
    hit.ns = -hit.ns;
  }
  if (dot(hit.ns, hit.ng) <= 0) hit.ns = hit.ng;
  return true;
}

bool Scene::occluded(const Vec3& origin, const Vec3& dir, float tmax) const {
  if (!rayIsValid(origin, dir, 0, tmax)) return true;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = origin.x; r.org_y = origin.y; r.org_z = origin.z;
  r.dir_x = dir.x; r.dir_y = dir.y; r.dir_z = dir.z;
  r.tnear = 0;
  r.tfar = tmax;
  r.time = 0;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(rtc_, &ctx, &r);
  return r.tfar < 0;
}

int Scene::firstHit(const Vec3& origin, const Vec3& dir, float tmax, float& t, int* prim) const {
  RTCIntersectContext ctx;
  if (!rayIsValid(origin, dir, 0, tmax)) return -1;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = rayHit(origin, dir, 0, tmax);
  rtcIntersect1(rtc_, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
  t = rh.ray.tfar;
  if (prim) *prim = int(rh.hit.primID);
  return int(rh.hit.geomID);
}

Color Scene::transmittance(const Vec3& origin, const Vec3& dir, float tmax) const {
  if (!hasTransmissive_ || !shadowsThroughGlass_) return occluded(origin, dir, tmax) ? Color(0) : Color(1);
  // Walk the hits along the segment, multiplying transmissive colours (the course
  // renderer's shadow attenuation); an opaque hit ends the walk.
  Color T(1);
  Vec3 o = origin;
  float remaining = tmax;
  for (int i = 0; i < 256 && remaining > 0; ++i) {
    Hit h;
    if (!intersect(Ray{o, dir, 0, remaining}, h)) return T;
    Color kt = shadingMaterial(h).kt;
    T *= kt;
    if (isBlack(T)) return Color(0);
    float step = h.t + epsilon_;
    o = h.p + dir * epsilon_;
    remaining -= step;
  }
  return T;
}

const Material& Scene::materialOf(const Hit& hit) const {
  const Shape& sh = shapes_[size_t(hit.shape)];
  if (sh.kind == ShapeKind::Mesh) {
    const Mesh& m = meshes_[size_t(sh.mesh)];
    if (!m.triangleMaterials.empty()) return materials_[size_t(m.triangleMaterials[size_t(hit.prim)])];
  }
  return materials_[size_t(sh.material)];
}

static void evalInto(const Material& m, const Vec2& uv, float w, ShadingMaterial& out) {
  out.ke += m.emissive.eval(uv) * w;
  out.ka += m.ambient.eval(uv) * w;
  out.kd += m.diffuse.eval(uv) * w;
  out.ks += m.specular.eval(uv) * w;
  out.kr += m.reflective.eval(uv) * w;
  out.kt += m.transmissive.eval(uv) * w;
  out.shininess += m.shininess.eval(uv) * w;
  out.ior += m.index.eval(uv) * w;
  // A luminous surface shows its luminosity colour unless the material sets `emissive`.
  if (m.luminosity && !m.emissiveSet) out.ke += m.luminosity->colour.eval(uv) * w;
}

ShadingMaterial Scene::shadingMaterial(const Hit& hit) const {
  ShadingMaterial sm;
  sm.ior = 0;
  const Shape& sh = shapes_[size_t(hit.shape)];
  if (sh.kind == ShapeKind::Mesh) {
    const Mesh& m = meshes_[size_t(sh.mesh)];
    if (!m.vertexMaterials.empty()) {
      // Per-vertex materials: blend every parameter barycentrically (as the course renderer did).
      const auto& tri = m.triangles[size_t(hit.prim)];
      for (int k = 0; k < 3; ++k)
        evalInto(materials_[size_t(m.vertexMaterials[size_t(tri[size_t(k)])])], hit.uv, hit.bary[k], sm);
      return sm;
    }
  }
  evalInto(materialOf(hit), hit.uv, 1.0f, sm);
  return sm;
}

Vec3 Scene::offsetOrigin(const Hit& hit, const Vec3& dir) const {
  // Off the surface and a step along the ray: from an edge where two surfaces meet, the
  // other surface's plane passes through the hit, and watertight hits would find it at t = 0.
  float len = length(dir);
  Vec3 along = len > 0 ? dir * (epsilon_ / len) : Vec3(0, 0, 0);
  return hit.p + hit.ng * (dot(dir, hit.ng) >= 0 ? epsilon_ : -epsilon_) + along;
}

}  // namespace lc::scene
