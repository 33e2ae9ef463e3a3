// Object lights (the seed's "luminosity"): every object whose material has a luminosity
// becomes many point lights on its surface when the scene loads.
//
// The keyword, inside a material (docs/SCENE_FORMAT.md):
//   luminosity = {
//     colour = (r,g,b) | map("file") | texture;   each light's colour, looked up at its uv
//                      (default (1,1,1); `texture` = the material's diffuse map)
//     intensity = I;   total emitted intensity of the object in point_light colour units
//                      (>= 0, default 1): the object's lights sum to I x mean colour
//     density = D;     lights per unit of WORLD-space area, after transforms (>= 0, default 1)
//     constant_attenuation_coeff = a; linear_attenuation_coeff = b;
//     quadratic_attenuation_coeff = c;   (>= 0, default 0, 0, 1) every light of the
//                      luminosity attenuates by min(1, 1/(a + b d + c d^2))
//   }
// Bad values (negative, NaN or infinite intensity/density/colour, negative coefficients)
// are errors at the luminosity's file:line:column, as is needing more than --max-lights
// lights in all; both are checked before any light is allocated. Intensity 0 adds nothing.
//
// Counts (round() is std::llround: halves away from zero):
//   mesh     triangle t of world area a_t gets n_t = max(1, round(a_t x D)) points, which is
//            its share a_t/A of the object's A x D, and at least one (at the centroid) as the
//            seed did, so D = 0 gives one per triangle. Zero-area triangles get none (no
//            area, no normal). With per-triangle materials (OBJ) each luminous material's
//            triangles form one object.
//   quadric  N = max(1, round(A x D)) points over the real world-space surface of area A
//            (caps included), split over its parts (faces, caps, body) in proportion to
//            their areas by largest remainder.
//   Every point of an object with N points has intensity I x colour(uv) / N, so the total
//   power I x mean colour does not depend on D. With `per_area` (what `emission = Le` makes)
//   I is per unit of world area: the total is I x A x colour, and a two-sided emitter under
//   oriented lights gets that on each side (an area A of radiance Le, Lambertian, emits flux
//   pi A Le per side, and an oriented light of intensity I emits pi I).
//
// Kinds:
//   oriented (default)  LightType::Oriented facing the outward unit normal (world space;
//            meshes: the winding normal cross(p1 - p0, p2 - p0)). Two-sided emitters (squares,
//            uncapped cylinders and cones, and area_light objects) get TWO lights per point
//            with opposite normals and half the intensity each. Other meshes emit along
//            their winding normal only, so a ceiling panel wastes no power into the ceiling.
//   omni     LightType::Omni, one per point (the seed's).
//   All lights of one luminosity share one LightGroup (its attenuation).
//
// Placement (the positions are on the surface; the renderer stops shadow rays short of a
// light, so the emitting surface does not shadow its own lights):
//   stratified (default)  triangles: the 2-D Hammersley set (i/n, radicalInverse2(i)),
//            toroidally shifted by (2/3, 2/3) so point 0 is the centroid, mapped to the
//            triangle by Heitz's low-distortion area-preserving map (2019). Quadric faces
//            and caps: the same set shifted by (1/2, 1/2) (point 0 at the centre), caps
//            through Shirley's concentric square-to-disk map. Curved parts: Halton points
//            (bases 2, 3 for the canonical surface, uniform in local area) kept when the
//            base-5 coordinate is below s(n)/s_max, where s(n) = |det M| |M^-T n| is the
//            local-to-world area scale at local unit normal n: uniform in WORLD area under
//            any affine M (non-uniform scale, shear).
//            --seed S (S != 1) shifts all of these point sets toroidally by a hash of S
//            (a Cranley-Patterson rotation): other positions, the same stratification.
//   seed     the seed's pattern on triangles (quadrics use the stratified sampler): point 0
//            at the centroid C; then k = max(1, round(sqrt((n_t - 1)/3))) points on each
//            line from C to vertex j at fractions l/(k+1), l = 1..k (levels l outer loop,
//            vertices 0,1,2 inner); the level-l points form a triangle similar to the
//            original; then rounds d = 1, 2, ...: on each edge of each level triangle the
//            points at fractions (2m-1)/2^d, m = 1..2^(d-1), levels from outer (l = k) to
//            inner, edges (0,1), (1,2), (2,0). Stops as soon as n_t points are placed,
//            mid-round if need be. n_t = 4 gives C and the midpoints of C-V0, C-V1, C-V2.
//
// World area of a transformed quadric: flat parts exactly (local area x s(n)); the sphere
// by Gauss-Legendre (128 nodes in latitude) x trapezoid (256 in longitude) of s(n) dA; the
// cylinder/cone body as (integral of r(z) dz) x trapezoid (4096 nodes, spectrally accurate
// for the periodic integrand) over the angle. Relative error < 1e-9 for axis ratios up to
// 100 (checked against closed-form spheroids in the tests).
//
// Deterministic: positions depend only on the geometry and the options; triangles are
// filled in parallel at offsets fixed by prefix sums, so any thread count gives the same
// lights in the same order.
#include "lights/object_lights.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/memory_budget.h"

namespace lc::lights {

namespace {

using io::ShapeKind;
using scene::Luminosity;
using scene::Shape;
using D3 = std::array<double, 3>;

constexpr double kPiD = 3.14159265358979323846;

// ---- low-discrepancy points -----------------------------------------------------------

double radicalInverseD(uint64_t base, uint64_t i) {
  double inv = 1.0 / double(base), f = inv, r = 0;
  while (i > 0) {
    r += f * double(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

double frac(double x) { return x - std::floor(x); }

// Point i of the n-point Hammersley set, toroidally shifted so point 0 lands on `shift`.
void shiftedHammersley(uint64_t i, uint64_t n, double shift, double& x, double& y) {
  x = frac(shift + double(i) / double(n));
  y = frac(shift + radicalInverseD(2, i));
}

// A toroidal shift of every point set by --seed (Cranley-Patterson rotation): other seeds
// place the lights elsewhere, still stratified; seed 1 (the default) shifts nothing, so the
// default lights are those of earlier releases.
struct SeedShift {
  double x = 0, y = 0;
  explicit SeedShift(uint64_t seed) {
    if (seed == 1) return;
    uint64_t h = seed * 0x9E3779B97F4A7C15ull;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    x = double(h >> 11) * 0x1p-53;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 32;
    y = double(h >> 11) * 0x1p-53;
  }
  void apply(double& u, double& v) const {
    u = frac(u + x);
    v = frac(v + y);
  }
};

// Heitz 2019, "A Low-Distortion Map Between Triangle and Square": area-preserving.
// (2/3, 2/3) maps to the centroid.
void squareToTriangle(double u0, double u1, double b[3]) {
  if (u0 < u1) {
    b[0] = u0 / 2;
    b[1] = u1 - b[0];
  } else {
    b[1] = u1 / 2;
    b[0] = u0 - b[1];
  }
  b[2] = 1 - b[0] - b[1];
}

// Shirley and Chiu's concentric map of [0,1]^2 to the unit disk; (1/2, 1/2) -> the centre.
void squareToDisk(double u, double v, double& x, double& y) {
  double a = 2 * u - 1, b = 2 * v - 1;
  if (a == 0 && b == 0) {
    x = y = 0;
    return;
  }
  double r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (kPiD / 4) * (b / a);
  } else {
    r = b;
    phi = kPiD / 2 - (kPiD / 4) * (a / b);
  }
  x = r * std::cos(phi);
  y = r * std::sin(phi);
}

// The seed's pattern (see the top of the file): calls emit(b) for the first n points.
template <class F>
void coursePattern(uint64_t n, F&& emit) {
  if (n == 0) return;
  const double c = 1.0 / 3;
  double b[3] = {c, c, c};
  emit(b);
  uint64_t left = n - 1;
  if (left == 0) return;
  uint64_t k = std::max<uint64_t>(1, uint64_t(std::llround(std::sqrt(double(left) / 3))));
  auto spoke = [&](uint64_t level, int v, double out[3]) {
    double t = double(level) / double(k + 1);
    for (int j = 0; j < 3; ++j) out[j] = (1 - t) * c + (j == v ? t : 0.0);
  };
  for (uint64_t level = 1; level <= k; ++level)
    for (int v = 0; v < 3; ++v) {
      spoke(level, v, b);
      emit(b);
      if (--left == 0) return;
    }
  for (int d = 1; d < 63; ++d) {
    uint64_t per = uint64_t(1) << (d - 1);
    double denom = std::ldexp(1.0, d);
    for (uint64_t level = k; level >= 1; --level)
      for (int e = 0; e < 3; ++e) {
        double a[3], z[3];
        spoke(level, e, a);
        spoke(level, (e + 1) % 3, z);
        for (uint64_t m = 1; m <= per; ++m) {
          double f = double(2 * m - 1) / denom;
          for (int j = 0; j < 3; ++j) b[j] = (1 - f) * a[j] + f * z[j];
          emit(b);
          if (--left == 0) return;
        }
      }
  }
}

// ---- quadric surfaces -------------------------------------------------------------------

// s(n) = |det M| |M^-T n|: how much the transform M scales area at local unit normal n.
struct AreaScale {
  double a[3][3] = {};  // |det M| M^-T
  explicit AreaScale(const Shape& s) {
    double det = std::fabs(s.toWorld.det3());
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) a[j][i] = det * s.toLocal.m[size_t(i)][size_t(j)];
  }
  D3 apply(const D3& n) const {
    return {a[0][0] * n[0] + a[0][1] * n[1] + a[0][2] * n[2], a[1][0] * n[0] + a[1][1] * n[1] + a[1][2] * n[2],
            a[2][0] * n[0] + a[2][1] * n[1] + a[2][2] * n[2]};
  }
  double operator()(const D3& n) const {
    D3 v = apply(n);
    return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  // The largest singular value: max of s(n) over all unit n (the sphere's rejection bound),
  // from the largest eigenvalue of A^T A (trigonometric closed form for 3x3 symmetric).
  double maxScale() const {
    double s[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] = a[0][i] * a[0][j] + a[1][i] * a[1][j] + a[2][i] * a[2][j];
    double p1 = s[0][1] * s[0][1] + s[0][2] * s[0][2] + s[1][2] * s[1][2];
    double lmax;
    if (p1 == 0) {
      lmax = std::max({s[0][0], s[1][1], s[2][2]});
    } else {
      double q = (s[0][0] + s[1][1] + s[2][2]) / 3;
      double p2 = (s[0][0] - q) * (s[0][0] - q) + (s[1][1] - q) * (s[1][1] - q) + (s[2][2] - q) * (s[2][2] - q) + 2 * p1;
      double p = std::sqrt(p2 / 6);
      double b[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b[i][j] = (s[i][j] - (i == j ? q : 0)) / p;
      double detB = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                    b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
      double r = std::clamp(detB / 2, -1.0, 1.0);
      lmax = q + 2 * p * std::cos(std::acos(r) / 3);
    }
    return std::sqrt(std::max(lmax, 0.0));
  }
};

enum class PartKind { Face, Disk, Sphere, Tube };

// One smooth piece of a quadric's surface, in the canonical frame.
struct Part {
  PartKind kind = PartKind::Face;
  int id = 0;  // the part number quadricUv/quadricLocalNormal use
  // Face: centre + (x - 1/2) e1 + (y - 1/2) e2 for (x, y) in [0,1]^2, normal `normal`.
  D3 centre{}, e1{}, e2{}, normal{};
  // Disk: radius `radius` in the plane z = z0, normal `normal` (0, 0, +-1).
  double z0 = 0, radius = 0;
  // Tube: radius r0 at z = 0 to r1 at z = h (a cylinder is 1, 1, 1).
  double r0 = 1, r1 = 1, h = 1;
  double area = 0;  // world space
  double sMax = 0;  // Sphere/Tube: upper bound on the rejection weight
  uint64_t count = 0;
};

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
void gaussLegendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(size_t(n), 0);
  w.assign(size_t(n), 0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double z = std::cos(kPiD * (i + 0.75) / (n + 0.5)), pp = 1;
    for (int it = 0; it < 100; ++it) {
      double p1 = 1, p2 = 0;
      for (int j = 1; j <= n; ++j) {
        double p3 = p2;
        p2 = p1;
        p1 = ((2.0 * j - 1) * z * p2 - (j - 1.0) * p3) / j;
      }
      pp = n * (z * p1 - p2) / (z * z - 1);
      double z1 = z;
      z = z1 - p1 / pp;
      if (std::fabs(z - z1) < 1e-15) break;
    }
    x[size_t(i)] = -z;
    x[size_t(n - 1 - i)] = z;
    w[size_t(i)] = w[size_t(n - 1 - i)] = 2 / ((1 - z * z) * pp * pp);
  }
}

constexpr int kSphereLatNodes = 128, kSphereLonNodes = 256, kTubeNodes = 4096;

D3 sphereNormal(double theta, double phi) {  // theta: colatitude
  double st = std::sin(theta);
  return {st * std::cos(phi), st * std::sin(phi), std::cos(theta)};
}

// Unnormalised outward normal of the tube at angle phi: (cos, sin, -k), k = dr/dz.
D3 tubeNormal(const Part& p, double phi) {
  return {std::cos(phi), std::sin(phi), -(p.r1 - p.r0) / p.h};
}

double sphereArea(const AreaScale& s) {
  static const auto nodes = [] {
    std::pair<std::vector<double>, std::vector<double>> xw;
    gaussLegendre(kSphereLatNodes, xw.first, xw.second);
    return xw;
  }();
  double sum = 0;
  for (int i = 0; i < kSphereLatNodes; ++i) {
    double theta = (nodes.first[size_t(i)] + 1) * kPiD / 2;
    double row = 0;
    for (int j = 0; j < kSphereLonNodes; ++j) row += s(sphereNormal(theta, 2 * kPiD * j / kSphereLonNodes));
    sum += nodes.second[size_t(i)] * std::sin(theta) * row;
  }
  return sum * (kPiD / 2) * (2 * kPiD / kSphereLonNodes);
}

// World area of a tube, and the bound on s over its (unnormalised) normals: the sampled
// maximum plus the Lipschitz constant |A e_x|+|A e_y| (bounding |d/dphi A n|) times half a step.
void tubeArea(const AreaScale& s, Part& p) {
  double sum = 0, mx = 0;
  for (int j = 0; j < kTubeNodes; ++j) {
    double v = s(tubeNormal(p, 2 * kPiD * j / kTubeNodes));
    sum += v;
    mx = std::max(mx, v);
  }
  double lip = s(D3{1, 0, 0}) + s(D3{0, 1, 0});
  p.sMax = mx + lip * kPiD / kTubeNodes;
  p.area = sum * (2 * kPiD / kTubeNodes) * p.h * (p.r0 + p.r1) / 2;
}

struct Quadric {
  std::vector<Part> parts;
  double area = 0;
};

Quadric describeQuadric(const Shape& sh) {
  AreaScale s(sh);
  Quadric q;
  auto face = [&](int id, D3 centre, D3 e1, D3 e2, D3 n) {
    Part p;
    p.kind = PartKind::Face;
    p.id = id;
    p.centre = centre;
    p.e1 = e1;
    p.e2 = e2;
    p.normal = n;
    p.area = s(n);  // the canonical faces have unit area
    q.parts.push_back(p);
  };
  auto disk = [&](int id, double z0, double r, double nz) {
    if (!(r > 0)) return;
    Part p;
    p.kind = PartKind::Disk;
    p.id = id;
    p.z0 = z0;
    p.radius = r;
    p.normal = {0, 0, nz};
    p.area = kPiD * r * r * s(p.normal);
    q.parts.push_back(p);
  };
  switch (sh.kind) {
    case ShapeKind::Sphere: {
      Part p;
      p.kind = PartKind::Sphere;
      p.area = sphereArea(s);
      p.sMax = s.maxScale() * (1 + 1e-9);
      q.parts.push_back(p);
      break;
    }
    case ShapeKind::Box:
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          double sign = side ? 1.0 : -1.0;
          D3 c{0, 0, 0}, n{0, 0, 0}, e1{0, 0, 0}, e2{0, 0, 0};
          c[size_t(axis)] = 0.5 * sign;
          n[size_t(axis)] = sign;
          e1[size_t((axis + 1) % 3)] = 1;
          e2[size_t((axis + 2) % 3)] = 1;
          face(2 * axis + side, c, e1, e2, n);
        }
      break;
    case ShapeKind::Square: face(0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}); break;
    case ShapeKind::Cylinder:
    case ShapeKind::Cone: {
      bool cyl = sh.kind == ShapeKind::Cylinder;
      Part p;
      p.kind = PartKind::Tube;
      p.r0 = cyl ? 1 : sh.bottomRadius;
      p.r1 = cyl ? 1 : sh.topRadius;
      p.h = cyl ? 1 : sh.height;
      tubeArea(s, p);
      q.parts.push_back(p);
      if (sh.capped) {
        disk(1, 0, p.r0, -1);
        disk(2, p.h, p.r1, 1);
      }
      break;
    }
    case ShapeKind::Mesh: break;
  }
  for (const Part& p : q.parts) q.area += p.area;
  return q;
}

// Splits n points over the parts in proportion to their areas (largest remainder; ties to
// the earlier part).
void allocate(Quadric& q, uint64_t n) {
  uint64_t given = 0;
  std::vector<std::pair<double, size_t>> rem;
  for (size_t i = 0; i < q.parts.size(); ++i) {
    double share = q.area > 0 ? double(n) * q.parts[i].area / q.area : 0;
    q.parts[i].count = uint64_t(std::floor(share));
    given += q.parts[i].count;
    rem.push_back({share - std::floor(share), i});
  }
  std::stable_sort(rem.begin(), rem.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; given < n && !rem.empty(); i = (i + 1) % rem.size(), ++given) ++q.parts[rem[i].second].count;
}

// ---- emitters ---------------------------------------------------------------------------

// One luminous object: a quadric, or the triangles of a mesh that carry one luminous material.
struct Emitter {
  int shape = -1;
  int material = -1;
  const Luminosity* lum = nullptr;
  bool twoSided = false;
  double area = 0;
  double points = 0;  // sample points (a double so that absurd counts cannot overflow)
  Quadric quadric;    // quadrics only
};

int triangleMaterial(const scene::Mesh& m, const Shape& sh, size_t t) {
  return m.triangleMaterials.empty() ? sh.material : m.triangleMaterials[t];
}

double triangleArea(const scene::Mesh& m, size_t t) {
  const auto& tri = m.triangles[t];
  const Vec3 &p0 = m.positions[size_t(tri[0])], &p1 = m.positions[size_t(tri[1])], &p2 = m.positions[size_t(tri[2])];
  D3 a{double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
  D3 b{double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
  D3 c{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

// Points on a triangle: its area times the density, at least one; none without area.
double trianglePoints(double area, double density) {
  if (!(area > 0)) return 0;
  return std::max(1.0, std::round(area * double(density)));
}

bool validNonNegative(float v) { return std::isfinite(v) && v >= 0; }

void validate(const Luminosity& l) {
  auto check = [&](float v, const char* what) {
    if (!validNonNegative(v))
      throw Error(l.loc, fmt::format("luminosity {} must be a finite number >= 0 (got {})", what, v));
  };
  check(l.intensity, "intensity");
  check(l.density, "density");
  check(l.attenConstant, "constant_attenuation_coeff");
  check(l.attenLinear, "linear_attenuation_coeff");
  check(l.attenQuadratic, "quadratic_attenuation_coeff");
  if (!l.colour.texture)
    for (int i = 0; i < 3; ++i) check(l.colour.value[i], "colour");
}

// Texture values outside [0, inf) (e.g. from an EXR) would make negative or NaN lights.
Color sanitize(Color c) {
  for (int i = 0; i < 3; ++i)
    if (!(c[i] >= 0) || !std::isfinite(c[i])) c[i] = 0;
  return c;
}

// Writes the light(s) of sample point k of an emitter.
struct Writer {
  Light* out = nullptr;
  const scene::TexColor* colour = nullptr;
  float perPoint = 0;  // intensity / N
  LightType type = LightType::Oriented;
  bool pair = false;   // two opposite oriented lights per point
  uint16_t group = 0;

  void put(uint64_t k, const Vec3& p, const Vec3& n, const Vec2& uv) const {
    Color c = sanitize(colour->eval(uv)) * perPoint;
    if (pair) {
      out[2 * k] = Light{p, n, c * 0.5f, LightType::Oriented, group};
      out[2 * k + 1] = Light{p, -n, c * 0.5f, LightType::Oriented, group};
    } else {
      out[k] = Light{p, n, c, type, group};
    }
  }
};

Vec3 toVec3(const D3& v) { return Vec3(float(v[0]), float(v[1]), float(v[2])); }

Vec3 worldNormal(const Shape& sh, const D3& nLocal) {
  D3 n{};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) n[size_t(j)] += sh.toLocal.m[size_t(i)][size_t(j)] * nLocal[size_t(i)];
  double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  return toVec3({n[0] / len, n[1] / len, n[2] / len});
}

void fillMesh(const scene::Scene& scene, const Emitter& e, const ObjectLightOptions& o, const Writer& w) {
  const Shape& sh = scene.shapes()[size_t(e.shape)];
  const scene::Mesh& m = scene.meshes()[size_t(sh.mesh)];
  const double density = e.lum->density;
  const SeedShift shift(o.seed);
  const size_t nt = m.triangles.size();
  // Prefix sums fix every triangle's first point index, so the parallel fill is deterministic.
  std::vector<uint64_t> first(nt + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    double n = triangleMaterial(m, sh, t) == e.material ? trianglePoints(triangleArea(m, t), density) : 0;
    first[t + 1] = first[t] + uint64_t(n);
  }
  auto cancelled = [&] { return o.cancel && o.cancel->load(std::memory_order_relaxed); };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nt, 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); ++t) {
      if (cancelled()) return;
      uint64_t n = first[t + 1] - first[t];
      if (n == 0) continue;
      const auto& tri = m.triangles[t];
      const Vec3 &p0 = m.positions[size_t(tri[0])], &p1 = m.positions[size_t(tri[1])], &p2 = m.positions[size_t(tri[2])];
      Vec3 normal = normalize(cross(p1 - p0, p2 - p0));
      uint64_t k = first[t];
      auto emit = [&](const double b[3]) {
        Vec3 p = p0 * float(b[0]) + p1 * float(b[1]) + p2 * float(b[2]);
        Vec2 uv = m.uvs.empty() ? Vec2(float(b[1]), float(b[2]))  // as Scene::intersect without uvs
                                : m.uvs[size_t(tri[0])] * float(b[0]) + m.uvs[size_t(tri[1])] * float(b[1]) +
                                      m.uvs[size_t(tri[2])] * float(b[2]);
        w.put(k++, p, normal, uv);
      };
      if (o.placement == Placement::Course) {
        coursePattern(n, emit);
      } else {
        for (uint64_t i = 0; i < n; ++i) {
          double x, y, b[3];
          shiftedHammersley(i, n, 2.0 / 3.0, x, y);
          shift.apply(x, y);
          squareToTriangle(x, y, b);
          emit(b);
        }
      }
    }
  });
  if (cancelled()) throw Interrupted();
}

void fillQuadric(const Shape& sh, const Emitter& e, const ObjectLightOptions& o, const Writer& w) {
  AreaScale s(sh);
  const SeedShift shift(o.seed);
  uint64_t k = 0;
  auto emit = [&](const D3& local, const D3& nLocal, int part) {
    if ((k & 0xffff) == 0 && o.cancel && o.cancel->load(std::memory_order_relaxed)) throw Interrupted();
    Vec3 pl = toVec3(local);
    w.put(k++, sh.toWorld.point(pl), worldNormal(sh, nLocal), quadricUv(sh, pl, part));
  };
  for (const Part& p : e.quadric.parts) {
    if (p.count == 0) continue;
    switch (p.kind) {
      case PartKind::Face:
        for (uint64_t i = 0; i < p.count; ++i) {
          double x, y;
          shiftedHammersley(i, p.count, 0.5, x, y);
          shift.apply(x, y);
          D3 q;
          for (int j = 0; j < 3; ++j) q[size_t(j)] = p.centre[size_t(j)] + (x - 0.5) * p.e1[size_t(j)] + (y - 0.5) * p.e2[size_t(j)];
          emit(q, p.normal, p.id);
        }
        break;
      case PartKind::Disk:
        for (uint64_t i = 0; i < p.count; ++i) {
          double x, y, dx, dy;
          shiftedHammersley(i, p.count, 0.5, x, y);
          shift.apply(x, y);
          squareToDisk(x, y, dx, dy);
          emit(D3{dx * p.radius, dy * p.radius, p.z0}, p.normal, p.id);
        }
        break;
      case PartKind::Sphere:
      case PartKind::Tube: {
        // Halton candidates, uniform in local area, kept with probability s(n)/sMax.
        uint64_t accepted = 0;
        const uint64_t maxTries = 1000 * p.count + 1000000;
        for (uint64_t i = 1; accepted < p.count; ++i) {
          if (i > maxTries)
            throw Error(sh.loc, "internal: object light sampling did not converge (a degenerate transform?)");
          double u = radicalInverseD(2, i), v = radicalInverseD(3, i), r = radicalInverseD(5, i);
          shift.apply(u, v);
          double phi = 2 * kPiD * v;
          D3 q, n;
          if (p.kind == PartKind::Sphere) {
            double z = 1 - 2 * u, rho = std::sqrt(std::max(0.0, 1 - z * z));
            q = {rho * std::cos(phi), rho * std::sin(phi), z};
            n = q;
          } else {
            // z with density proportional to r(z) = r0 + kz (the local area of a ring).
            double kz = (p.r1 - p.r0) / p.h;
            double T = u * p.h * (p.r0 + p.r1) / 2;
            double den = p.r0 + std::sqrt(std::max(0.0, p.r0 * p.r0 + 2 * kz * T));
            double z = den > 0 ? std::min(p.h, 2 * T / den) : 0;
            double rz = p.r0 + kz * z;
            q = {rz * std::cos(phi), rz * std::sin(phi), z};
            n = tubeNormal(p, phi);
          }
          if (r * p.sMax >= s(n)) continue;
          double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
          emit(q, D3{n[0] / len, n[1] / len, n[2] / len}, p.id);
          ++accepted;
        }
        break;
      }
    }
  }
}

std::string countText(double n) {
  return n < 1e18 ? std::to_string(uint64_t(n)) : fmt::format("{:.3g}", n);
}

}  // namespace

std::vector<ObjectLightInfo> addObjectLights(scene::Scene& scene, const ObjectLightOptions& options) {
  const auto& materials = scene.materials();
  for (const auto& m : materials)
    if (m.luminosity) validate(*m.luminosity);

  // Pass 1: every emitter and its point count, with nothing allocated for lights yet.
  std::vector<Emitter> emitters;
  const auto& shapes = scene.shapes();
  for (size_t si = 0; si < shapes.size(); ++si) {
    const Shape& sh = shapes[si];
    auto luminous = [&](int mi) { return mi >= 0 && size_t(mi) < materials.size() && materials[size_t(mi)].luminosity; };
    if (sh.kind == ShapeKind::Mesh) {
      const scene::Mesh& m = scene.meshes()[size_t(sh.mesh)];
      std::vector<int> mats;  // luminous materials in order of first use
      if (m.triangleMaterials.empty()) {
        if (luminous(sh.material)) mats.push_back(sh.material);
      } else {
        for (int mi : m.triangleMaterials)
          if (luminous(mi) && std::find(mats.begin(), mats.end(), mi) == mats.end()) mats.push_back(mi);
      }
      for (int mi : mats) {
        Emitter e;
        e.shape = int(si);
        e.material = mi;
        e.lum = &*materials[size_t(mi)].luminosity;
        e.twoSided = sh.twoSidedEmission;
        for (size_t t = 0; t < m.triangles.size(); ++t) {
          if (triangleMaterial(m, sh, t) != mi) continue;
          double a = triangleArea(m, t);
          e.area += a;
          e.points += trianglePoints(a, e.lum->density);
        }
        if (e.lum->intensity > 0 && e.points > 0) emitters.push_back(std::move(e));
      }
    } else if (luminous(sh.material)) {
      Emitter e;
      e.shape = int(si);
      e.material = sh.material;
      e.lum = &*materials[size_t(sh.material)].luminosity;
      if (sh.kind == ShapeKind::Cone && !(sh.height > 0 && sh.bottomRadius >= 0 && sh.topRadius >= 0 &&
                                          sh.bottomRadius + sh.topRadius > 0))
        throw Error(sh.loc, "a luminous cone needs height > 0 and radii >= 0, not both 0");
      bool open = (sh.kind == ShapeKind::Cylinder || sh.kind == ShapeKind::Cone) && !sh.capped;
      e.twoSided = sh.twoSidedEmission || sh.kind == ShapeKind::Square || open;
      e.quadric = describeQuadric(sh);
      e.area = e.quadric.area;
      e.points = e.area > 0 ? std::max(1.0, std::round(e.area * double(e.lum->density))) : 0;
      if (!std::isfinite(e.area)) e.points = std::numeric_limits<double>::infinity();
      if (e.lum->intensity > 0 && e.points > 0) emitters.push_back(std::move(e));
    }
  }

  const bool oriented = options.kind == ObjectLightKind::Oriented;
  auto perPoint = [&](const Emitter& e) { return oriented && e.twoSided ? 2.0 : 1.0; };
  const double existing = double(scene.lights().size());
  double total = 0;
  for (const Emitter& e : emitters) total += e.points * perPoint(e);
  if (existing + total > double(options.maxLights)) {
    // Report at the luminosity whose object pushes the count over the limit.
    double running = existing;
    const Emitter* culprit = &emitters.back();
    for (const Emitter& e : emitters) {
      running += e.points * perPoint(e);
      if (running > double(options.maxLights)) {
        culprit = &e;
        break;
      }
    }
    throw Error(culprit->lum->loc,
                fmt::format("luminous objects need {} lights ({} with the scene's other lights), more "
                            "than --max-lights ({})",
                            countText(total), countText(existing + total), options.maxLights));
  }

  if (!emitters.empty()) {
    const uint64_t bytes = uint64_t(total) * memory_cost::kLight;
    if (!processBudget().tryReserve(bytes))
      throw Error(emitters.front().lum->loc,
                  processBudget().overBudget(bytes, "the " + countText(total) + " lights of luminous objects"));
  }

  // Pass 2: allocate once, then fill each emitter's range.
  LightSet& set = scene.lights();
  std::vector<ObjectLightInfo> infos;
  size_t base = set.lights.size();
  set.lights.resize(base + size_t(total));
  Progress progress(options.progress, total);
  for (Emitter& e : emitters) {
    if (options.cancel && options.cancel->load()) throw Interrupted();
    const Luminosity& l = *e.lum;
    LightGroup g;
    g.atten = Attenuation{l.attenConstant, l.attenLinear, l.attenQuadratic, kInf};
    if (!set.hasRoomFor(g)) throw Error(l.loc, "too many distinct light groups (attenuations) in the scene");
    Writer w;
    w.out = set.lights.data() + base;
    w.colour = &l.colour;
    w.type = oriented ? LightType::Oriented : LightType::Omni;
    w.pair = oriented && e.twoSided;
    // per_area (emission): intensity x world area, on each side of a two-sided emitter.
    double power = double(l.intensity) * (l.perArea ? e.area * (w.pair ? 2.0 : 1.0) : 1.0);
    if (!(power / e.points <= double(std::numeric_limits<float>::max())))
      throw Error(l.loc, fmt::format("emission x area ({:.3g}) is out of range for a float", power));
    w.perPoint = float(power / e.points);
    w.group = set.groupFor(g);
    const Shape& sh = scene.shapes()[size_t(e.shape)];
    if (sh.kind == ShapeKind::Mesh) {
      fillMesh(scene, e, options, w);
    } else {
      allocate(e.quadric, uint64_t(e.points));
      fillQuadric(sh, e, options, w);
    }
    size_t n = size_t(e.points * perPoint(e));
    ObjectLightInfo info;
    info.shape = e.shape;
    info.name = sh.name;
    info.lights = n;
    info.area = e.area;
    double pw[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) pw[c] += w.out[i].intensity[c];
    info.power = Color(float(pw[0]), float(pw[1]), float(pw[2]));
    infos.push_back(std::move(info));
    base += n;
    progress.add(double(n));
  }
  return infos;
}

}  // namespace lc::lights
