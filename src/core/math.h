// Small vector/matrix types used everywhere. Floats for rendering; Mat4 keeps doubles
// so that long chains of nested transforms lose no precision before they are baked.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace lc {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Vec2 {
  float x = 0, y = 0;
  constexpr Vec2() = default;
  constexpr Vec2(float x_, float y_) : x(x_), y(y_) {}
  constexpr Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2 operator*(float s) const { return {x * s, y * s}; }
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}
  constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
  constexpr Vec3 operator/(const Vec3& o) const { return {x / o.x, y / o.y, z / o.z}; }
  constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(float s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(const Vec3& o) { x *= o.x; y *= o.y; z *= o.z; return *this; }
  constexpr Vec3& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
  constexpr Vec3& operator/=(float s) { x /= s; y /= s; z /= s; return *this; }
  constexpr bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3& o) const { return !(*this == o); }
};

// Colours share the vector type: RGB, linear.
using Color = Vec3;

constexpr Vec3 operator*(float s, const Vec3& v) { return v * s; }
constexpr float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3& v) { return std::sqrt(dot(v, v)); }
constexpr float length2(const Vec3& v) { return dot(v, v); }
inline Vec3 normalize(const Vec3& v) {
  float l = length(v);
  return l > 0 ? v / l : v;
}
// normalize() for vectors whose squared length overflows or underflows a float (a
// direction of (1e20,1e20,-1e20) or (1e-30,0,0)): divides by the largest component
// first. Scene setup only (it costs a few more operations than normalize). A zero or
// non-finite vector comes back unchanged.
inline Vec3 normalizeScaled(const Vec3& v) {
  float m = std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z)));
  if (!(m > 0) || !std::isfinite(m)) return v;
  Vec3 s = v / m;
  return s / std::sqrt(dot(s, s));
}
// length() that neither overflows nor underflows in the squared length (components near
// 1e20 or 1e-20): scales by the largest component when the plain square is out of range.
inline float lengthScaled(const Vec3& v) {
  float l2 = dot(v, v);
  if (l2 >= std::numeric_limits<float>::min() && l2 <= std::numeric_limits<float>::max())
    return std::sqrt(l2);
  float m = std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z)));
  if (!(m > 0) || !std::isfinite(m)) return m;
  Vec3 s = v / m;
  return m * std::sqrt(dot(s, s));
}
constexpr Vec3 vmin(const Vec3& a, const Vec3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3 vmax(const Vec3& a, const Vec3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline Vec3 vabs(const Vec3& a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
constexpr float maxComponent(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
constexpr float minComponent(const Vec3& v) { return std::min(v.x, std::min(v.y, v.z)); }
// Rec. 709 luminance: the scalar every error threshold and metric is measured in.
constexpr float luminance(const Color& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
constexpr bool isBlack(const Color& c) { return c.x == 0 && c.y == 0 && c.z == 0; }
inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
constexpr Vec3 lerp(float t, const Vec3& a, const Vec3& b) { return a * (1 - t) + b * t; }

// A double-precision vector for sums that run over many terms: light intensities summed up a
// tree, brute force over every light, weighted means over millions of lights. A float sum
// of N similar terms drops each term's bits below the running sum's ulp; at 8.1M lights
// (the Cornell box at --vpls 10000000) a brute-force pixel lost up to 8% of its light that
// way. Values are stored back in float (Vec3) once summed.
struct Vec3d {
  double x = 0, y = 0, z = 0;
  constexpr Vec3d() = default;
  constexpr Vec3d(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  constexpr explicit Vec3d(const Vec3& v) : x(v.x), y(v.y), z(v.z) {}

  constexpr Vec3d operator+(const Vec3d& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3d operator-(const Vec3d& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3d operator/(double s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3d& operator+=(const Vec3d& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3d& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3d& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  // Rounded to float, each component once.
  constexpr Vec3 toFloat() const { return {float(x), float(y), float(z)}; }
};
constexpr double luminance(const Vec3d& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Reflect v about n (both pointing away from the surface): r = 2(n.v)n - v.
constexpr Vec3 reflect(const Vec3& v, const Vec3& n) { return n * (2 * dot(n, v)) - v; }

// x^e for x >= 0: by repeated squaring when e is a whole number up to 1024 (Phong
// exponents mostly are; a few multiplies instead of std::pow's exp/log), else std::pow.
// Monotone in x like std::pow (each rounded product is), so the light bounds that call it
// stay above the contributions that call it.
inline float powNonNegative(float x, float e) {
  if (e >= 0 && e <= 1024 && e == float(int(e))) {
    float r = 1, b = x;
    for (int k = int(e); k != 0; k >>= 1) {
      if (k & 1) r *= b;
      b *= b;
    }
    return r;
  }
  return std::pow(x, e);
}

// An orthonormal basis with w = n (Duff et al. 2017, "Building an orthonormal basis, revisited").
inline void orthonormalBasis(const Vec3& n, Vec3& u, Vec3& v) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  u = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  v = Vec3(b, sign + n.y * n.y * a, -n.y);
}

struct Bounds3 {
  Vec3 lo{kInf, kInf, kInf};
  Vec3 hi{-kInf, -kInf, -kInf};
  constexpr Bounds3() = default;
  constexpr Bounds3(const Vec3& a, const Vec3& b) : lo(vmin(a, b)), hi(vmax(a, b)) {}
  constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  constexpr void extend(const Vec3& p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  constexpr void extend(const Bounds3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  constexpr Vec3 center() const { return (lo + hi) * 0.5f; }
  constexpr Vec3 extent() const { return hi - lo; }
  inline float diagonal() const { return empty() ? 0.0f : lengthScaled(hi - lo); }
  constexpr float diagonal2() const { return empty() ? 0.0f : length2(hi - lo); }
  // Squared distance from p to the closest point of the box (0 inside).
  constexpr float distance2(const Vec3& p) const {
    Vec3 d = vmax(vmax(lo - p, Vec3(0.0f)), p - hi);
    return dot(d, d);
  }
};

inline Bounds3 merge(const Bounds3& a, const Bounds3& b) {
  Bounds3 r = a;
  r.extend(b);
  return r;
}

// p's place along a Morton (Z-order) curve through `b`, 10 bits per axis: points close in
// space are mostly close in this order (the light tree's bottom-up groups; the VPLs' order
// in the light array).
inline uint32_t mortonCode(const Vec3& p, const Bounds3& b) {
  auto spread = [](uint32_t x) {
    x = (x | (x << 16)) & 0x030000FFu;
    x = (x | (x << 8)) & 0x0300F00Fu;
    x = (x | (x << 4)) & 0x030C30C3u;
    x = (x | (x << 2)) & 0x09249249u;
    return x;
  };
  Vec3 e = b.extent();
  uint32_t q[3];
  for (int i = 0; i < 3; ++i) {
    float t = e[i] > 0 ? (p[i] - b.lo[i]) / e[i] : 0.5f;
    q[i] = uint32_t(std::clamp(t * 1023.0f, 0.0f, 1023.0f));
  }
  return (spread(q[0]) << 2) | (spread(q[1]) << 1) | spread(q[2]);
}

// Row-major 4x4 affine matrix, applied to column vectors: p' = M p.
struct Mat4 {
  std::array<std::array<double, 4>, 4> m{};

  static Mat4 identity() {
    Mat4 r;
    for (int i = 0; i < 4; ++i) r.m[i][i] = 1;
    return r;
  }
  static Mat4 translate(double x, double y, double z) {
    Mat4 r = identity();
    r.m[0][3] = x; r.m[1][3] = y; r.m[2][3] = z;
    return r;
  }
  static Mat4 scale(double x, double y, double z) {
    Mat4 r = identity();
    r.m[0][0] = x; r.m[1][1] = y; r.m[2][2] = z;
    return r;
  }
  // Rotation by `angle` radians about `axis` (normalised here; a zero axis gives identity).
  static Mat4 rotate(double ax, double ay, double az, double angle) {
    double len = std::sqrt(ax * ax + ay * ay + az * az);
    if (len == 0) return identity();
    ax /= len; ay /= len; az /= len;
    double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    Mat4 r = identity();
    r.m[0][0] = t * ax * ax + c;      r.m[0][1] = t * ax * ay - s * az; r.m[0][2] = t * ax * az + s * ay;
    r.m[1][0] = t * ax * ay + s * az; r.m[1][1] = t * ay * ay + c;      r.m[1][2] = t * ay * az - s * ax;
    r.m[2][0] = t * ax * az - s * ay; r.m[2][1] = t * ay * az + s * ax; r.m[2][2] = t * az * az + c;
    return r;
  }

  Mat4 operator*(const Mat4& o) const {
    Mat4 r;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double s = 0;
        for (int k = 0; k < 4; ++k) s += m[i][k] * o.m[k][j];
        r.m[i][j] = s;
      }
    return r;
  }
  Vec3 point(const Vec3& p) const {
    return Vec3(float(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3]),
                float(m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3]),
                float(m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]));
  }
  Vec3 vector(const Vec3& v) const {
    return Vec3(float(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z),
                float(m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z),
                float(m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z));
  }
  // Normals transform by the inverse transpose: pass the inverse matrix here.
  Vec3 normalFromInverse(const Vec3& n) const {
    return Vec3(float(m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z),
                float(m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z),
                float(m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z));
  }
  double det3() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  // Inverse of an affine matrix; returns false when the 3x3 part is singular.
  bool inverseAffine(Mat4& out) const {
    double d = det3();
    if (!(std::fabs(d) > 1e-300) || !std::isfinite(d)) return false;
    double id = 1.0 / d;
    Mat4 r = identity();
    r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * id;
    r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
    r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
    r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * id;
    r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
    r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
    r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * id;
    r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
    r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
    for (int i = 0; i < 3; ++i)
      r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
    out = r;
    return true;
  }
  bool isFinite() const {
    for (auto& row : m)
      for (double v : row)
        if (!std::isfinite(v)) return false;
    return true;
  }
};

}  // namespace lc
