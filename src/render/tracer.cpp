#include "render/tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <time.h>

#include "core/multi_jitter.h"
#include "core/rng.h"

namespace lc::render {

namespace {

using Clock = std::chrono::steady_clock;

uint64_t threadCpuNanos() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return uint64_t(ts.tv_sec) * 1'000'000'000u + uint64_t(ts.tv_nsec);
}

}  // namespace

// Multi-jittered (core/multi_jitter.h) on the squarest a x b grid with a b = spp, a >= b:
// 8 x 8 for 64, 6 x 4 for 24, 7 x 1 for 7 (a Latin hypercube). One sample takes the centre.
void pixelSamplePositions(int spp, Rng& rng, std::vector<Vec2>& out) {
  if (spp <= 1) {
    out.assign(1, Vec2(0.5f, 0.5f));
    return;
  }
  int b = int(std::sqrt(double(spp)));
  while (spp % b != 0) --b;
  multiJittered(spp / b, b, rng, out);
}

Color ShadowRays::operator()(const Vec3& wi, float dist) {
  return timed([&] {
    float tmax;
    Vec3 dir;
    Vec3 o = origin(wi, dist, tmax, dir);
    if (!(tmax > 0)) return Color(1);
    return scene_.transmittance(o, dir, tmax);
  });
}

Color ShadowRays::trace(const Vec3& wi, float dist, int& blocker, float& tHit) {
  return timed([&] {
    float tmax;
    Vec3 dir;
    Vec3 o = origin(wi, dist, tmax, dir);
    blocker = kVisible;
    tHit = 0;
    if (!(tmax > 0)) return Color(1);
    int prim = 0;
    int shape = scene_.firstHit(o, dir, tmax, tHit, &prim);
    if (shape < 0) return Color(1);
    if (scene_.isTransmissive(shape)) {  // glass on the way: the walk through it decides
      Color v = scene_.transmittance(o, dir, tmax);
      blocker = isBlack(v) ? kUnknownBlocker : kVisible;
      return v;
    }
    if (scene_.isConvex(shape)) {
      blocker = shape;
    } else {
      // A triangle of a non-convex mesh: the flat convex face it is part of, numbered
      // after the shapes.
      const int face = scene_.planarFaces().faceOf(shape, prim);
      blocker = face >= 0 ? int(scene_.shapes().size()) + face : kUnknownBlocker;
    }
    return Color(0);
  });
}

// Rays toward a box in front of the point's surface leave from p' = p + ng eps (and a step
// along the ray) and end 2 eps short of the light (origin()): each is part of the segment
// from p' toward a point of the box, ending 2 eps before it. The convex shape the point
// lies on (hit from outside) is behind its tangent plane, which the box is in front of: no
// ray re-enters it.
bool ShadowRays::boxClear(const Vec3& lo, const Vec3& hi, uint32_t& hint) {
  const Vec3 c = (lo + hi) * 0.5f, h = (hi - lo) * 0.5f;
  if (!scene_.occluders().built() || !(dot(ng_, c - p_) - dot(vabs(ng_), h) > 2 * eps_)) return false;
  return scene_.occluders().clear(p_ + ng_ * eps_, lo, hi, 0.1f * eps_, 2 * eps_, ownShape_, &hint);
}

// A ray leaves from p + ng eps plus a step of eps along it (origin()), so it lies within
// 2 eps of the segment from p the probe tests; the bounds are padded by that and by their
// own float rounding.
bool ShadowRays::blockerBox(int blocker, Vec3& lo, Vec3& hi) const {
  const int face = faceOf(blocker);
  if (face < 0 && !convexShape(blocker)) return false;
  const Bounds3& b = face >= 0 ? scene_.planarFaces().bounds(face) : scene_.convexBounds(blocker);
  if (b.empty()) return false;
  const Vec3 big = vmax(vabs(b.lo), vabs(b.hi));
  const float pad = 4 * eps_ + 1e-5f * std::max({big.x, big.y, big.z, length(p_)});
  if (!std::isfinite(pad)) return false;
  lo = b.lo - Vec3(pad);
  hi = b.hi + Vec3(pad);
  return true;
}

// A shadow ray leaves from within 2 eps of p (origin()) and so runs within 2 eps of the
// segment from p to its light, ending 3 eps short of it. The corners' segments stand for
// those (the directions that meet a convex body's inside, shrunk by a margin, within a
// distance form a convex cone): one that passes through the blocker 4 eps deep (plus the
// coordinates' rounding), from that margin past p to that margin before tMax, stops the
// rays too. Boxes, spheres and capped cylinders are decided exactly
// (scene::SolidWithMargin), and so are closed convex meshes and the flat faces of other
// meshes (scene::PlanarFaces, which widens a face's margin by 1/cos of the crossing's slant:
// a flat face has no depth); other shapes are left to the rays.
int ShadowRays::blocksAll(int blocker, const Vec3* dirs, int n, float tMax) const {
  const float margin = 4 * eps_ + 1e-5f * (length(p_) + tMax);
  if (!std::isfinite(margin)) return -1;
  // A mesh's flat face: every segment crosses it well inside its edges (planar_faces.h).
  if (const int face = faceOf(blocker); face >= 0)
    return scene_.planarFaces().crossesAll(face, p_, dirs, n, tMax, margin);
  if (!convexShape(blocker)) return -1;
  // A convex mesh: its faces' planes, moved in by the margin, clip each segment; a square
  // is a face.
  if (scene_.shapes()[size_t(blocker)].kind == io::ShapeKind::Mesh)
    return scene_.planarFaces().solidMeetsAll(blocker, p_, dirs, n, tMax, margin);
  if (const int face = scene_.planarFaces().squareFace(blocker); face >= 0)
    return scene_.planarFaces().crossesAll(face, p_, dirs, n, tMax, margin);
  const scene::SolidWithMargin solid(scene_.shapes()[size_t(blocker)], margin);
  // From inside the shape (a room modelled as one box, seen from within) a segment runs
  // through it without crossing its surface: the rays decide, as before.
  if (!solid.decides() || !solid.surelyOutside(p_)) return -1;
  for (int i = 0; i < n; ++i)
    if (!solid.surelyMeets(p_, dirs[i], margin, tMax - margin)) return 0;
  return 1;
}

// The ray: from p' = p + ng eps, off the surface on the light's side, toward the light
// itself (p + wi dist); it starts a step of eps along the way and ends 2 eps short of the
// light. The step matters on an edge where two surfaces meet (a room's corner): the point
// lies in the other surface's plane, and watertight hits (issue 29) would count that
// surface at t = 0 and shadow the edge. The ray aims at the light, not at the light moved
// by ng eps as it did: for a light on a surface that p's surface faces (a VPL on a wall
// seen from a box's side, a ceiling panel seen from the floor) that end lay behind the
// light's surface wherever the ray met it at a slant (cos below half of -ng . n_light, up
// to 1/2), and the ray hit that surface: the red wall's VPLs were hidden from the Cornell
// box's tall block, in brute force and lightcuts alike (docs/LIGHTCUTS.md, "Shadow rays
// that end behind their light").
Vec3 ShadowRays::origin(const Vec3& wi, float dist, float& tmax, Vec3& dir) const {
  const Vec3 lift = ng_ * (dot(wi, ng_) >= 0 ? eps_ : -eps_);
  const Vec3 start = p_ + lift;
  if (std::isinf(dist)) {
    dir = wi;
    tmax = kInf;
    return start + wi * eps_;
  }
  const Vec3 d = wi * dist - lift;  // (p + wi dist) - p', without adding and subtracting p
  const float len = length(d);
  if (!(len > 0) || std::isinf(len)) {  // a light at p, or so far that |d|^2 overflows
    dir = wi;
    tmax = dist - 3 * eps_;
    return start + wi * eps_;
  }
  dir = d / len;
  tmax = len - 3 * eps_;
  return start + dir * eps_;
}

template <class F>
Color ShadowRays::timed(const F& f) {
  if (!stats_) return f();
  ++stats_->tracedRays;
  static thread_local uint64_t state = 0x9e3779b97f4a7c15ull;
  state ^= state << 13, state ^= state >> 7, state ^= state << 17;  // xorshift64
  if (state % kTimedRayOdds != 0) return f();
  // t1 - t0 is one clock read: taken off the ray's interval, which holds one too.
  auto t0 = Clock::now(), t1 = Clock::now();
  Color c = f();
  auto t2 = Clock::now();
  const int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>((t2 - t1) - (t1 - t0)).count();
  if (ns <= kMaxTimedRayNs) {
    ++stats_->timedRays;
    stats_->timedRayNanos += uint64_t(std::max<int64_t>(ns, 0));
  }
  return c;
}

lightcuts::EvalResult Tracer::directLight(const scene::Hit& h, const lightcuts::ShadingPoint& sp, int depth) {
  ++stats.litPoints;
  static thread_local uint64_t state = 0x2545f4914f6cdd1dull;
  state ^= state << 13, state ^= state >> 7, state ^= state << 17;  // xorshift64
  if (state % kTimedPointOdds != 0) return evaluateLight(h, sp, depth);
  const uint64_t t0 = threadCpuNanos();
  lightcuts::EvalResult r = evaluateLight(h, sp, depth);
  stats.lightingNanos += threadCpuNanos() - t0;
  ++stats.timedPoints;
  return r;
}

lightcuts::EvalResult Tracer::evaluateLight(const scene::Hit& h, const lightcuts::ShadingPoint& sp, int depth) {
  ShadowRays vis(scene, h, &stats);
  if (depth > 0 || !hook) return evaluator.evaluate(sp, vis, stats);
  return hook->light(h, sp, vis, stats);
}

Color Tracer::trace(const scene::Ray& ray, int depth, float weight) {
  scene::Hit h;
  // A ray that escapes sees the environment (camera, reflected and refracted rays alike).
  if (!scene.intersect(ray, h)) return scene.background(normalize(ray.d));
  scene::ShadingMaterial m = scene.shadingMaterial(h);
  Color L = m.ke + m.ka * scene.ambient();
  Vec3 v = -normalize(ray.d);
  if (!isBlack(m.kd) || !isBlack(m.ks)) {
    lightcuts::ShadingPoint sp;
    sp.p = h.p;
    sp.n = h.ns;
    sp.r = normalize(reflect(v, h.ns));
    sp.kd = m.kd;
    sp.ks = m.ks;
    sp.shininess = m.shininess;
    sp.errorFloor = errorFloor > 0 && weight > 0 ? errorFloor / weight : 0;
    sp.minError = minError;
    sp.clearTests = clearTests;
    lightcuts::EvalResult r = directLight(h, sp, depth);
    L += r.radiance;
    cutNodes += r.cutSize;
  }
  if (depth >= maxDepth) return L;
  if (!isBlack(m.kr)) {
    Vec3 r = normalize(reflect(v, h.ns));
    // A non-finite direction (NaN normal, extreme values) is dropped, not traced.
    if (isFinite(r)) {
      ++secondaryRays;
      L += m.kr * trace(scene::Ray{scene.offsetOrigin(h, r), r, 0, kInf}, depth + 1, weight * luminance(m.kr));
    }
  }
  if (!isBlack(m.kt)) {
    // Entering through the front face goes from air (index 1) into the material.
    float eta = h.frontFace ? 1.0f / m.ior : m.ior;
    float cosI = std::min(1.0f, dot(v, h.ns));
    float sin2T = eta * eta * (1 - cosI * cosI);
    Vec3 t;
    // (written so that a NaN sin2T, e.g. inf * 0 for a huge index, is total reflection)
    if (!(sin2T < 1)) {
      t = normalize(reflect(v, h.ns));  // total internal reflection
    } else {
      t = normalize(-v * eta + h.ns * (eta * cosI - std::sqrt(1 - sin2T)));
    }
    // A refracted ray with a non-finite direction is dropped, not traced.
    if (isFinite(t)) {
      ++secondaryRays;
      L += m.kt * trace(scene::Ray{scene.offsetOrigin(h, t), t, 0, kInf}, depth + 1, weight * luminance(m.kt));
    }
  }
  return L;
}

Color traceRay(const scene::Scene& scene, const lightcuts::LightEvaluator& evaluator, const scene::Ray& ray,
               int maxDepth, lightcuts::EvalStats& stats) {
  Tracer tr{scene, evaluator, maxDepth, stats};
  return tr.trace(ray, 0);
}

void Tracer::cutSettingsFrom(const RenderOptions& o) {
  errorFloor = std::max(0.0f, o.errorFloor);
  minError = o.minError;
  clearTests = o.clearTests;
}

PixelResult renderPixel(const scene::Scene& scene, const lightcuts::LightEvaluator& ev, const RenderOptions& o, int x,
                        int y, lightcuts::EvalStats& stats, uint64_t& primary, uint64_t& secondary,
                        PrimaryLight* hook) {
  Rng rng(o.seed, uint64_t(y) * uint64_t(o.width) + uint64_t(x));
  const uint64_t rays0 = stats.shadowRays;
  Tracer tr{scene, ev, o.maxDepth, stats, hook};
  tr.cutSettingsFrom(o);
  Color sum(0);
  const scene::Camera& cam = scene.camera();
  static thread_local std::vector<Vec2> positions;
  pixelSamplePositions(o.spp, rng, positions);
  for (int s = 0; s < o.spp; ++s) {
    const Vec2 u = positions[size_t(s)];
    float sx = (float(x) + u.x) / float(o.width), sy = (float(y) + u.y) / float(o.height);
    scene::Ray ray{cam.eye, normalize(cam.direction(sx, sy)), 0, kInf};
    ++primary;
    Color c = tr.trace(ray, 0);
    if (!isFinite(c)) c = Color(0);  // never let a NaN reach the image
    sum += c;
  }
  secondary += tr.secondaryRays;
  return {sum / float(o.spp), float(tr.cutNodes) / float(o.spp), float(stats.shadowRays - rays0) / float(o.spp)};
}

void storePixel(RenderResult& res, int width, int x, int y, const PixelResult& p) {
  size_t i = size_t(y) * size_t(width) + size_t(x);
  res.image.pixels[i] = p.color;
  res.cutSize[i] = p.cut;
  res.shadowRays[i] = p.shadowRays;
  res.done[i] = 1;
}

}  // namespace lc::render
