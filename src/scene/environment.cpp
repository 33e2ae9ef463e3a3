#include "scene/environment.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lc::scene {

namespace {

// Right-handed rotation of v about unit axis k by angle a.
Vec3 rotateAbout(const Vec3& v, const Vec3& k, double a) {
  float c = float(std::cos(a)), s = float(std::sin(a));
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

// The sky table's resolution: fine enough that the circumsolar peak spans several pixels.
constexpr int kSkyWidth = 512, kSkyHeight = 256;

}  // namespace

Vec3 Environment::direction(double u, double v) const {
  double phi = 2 * kPi * (u - 0.5), theta = kPi * v;
  double st = std::sin(theta);
  Vec3 local(float(st * std::sin(phi)), float(std::cos(theta)), float(-st * std::cos(phi)));
  return normalize(ex_ * local.x + ey_ * local.y + ez_ * local.z);
}

void Environment::coordinates(const Vec3& d, double& u, double& v) const {
  double lx = dot(d, ex_), ly = dot(d, ey_), lz = dot(d, ez_);
  double phi = std::atan2(lx, -lz);
  u = 0.5 + phi / (2 * kPi);
  v = std::acos(std::clamp(ly / std::max(1e-30, std::sqrt(lx * lx + ly * ly + lz * lz)), -1.0, 1.0)) / kPi;
}

Environment Environment::build(const io::EnvironmentDesc& d, const Limits& limits) {
  Environment e;
  e.kind_ = d.kind;
  e.lights_ = d.lights;
  e.visible_ = d.visible;
  e.loc_ = d.loc;
  if (d.kind == io::EnvironmentKind::Map) {
    if (!(d.intensity >= 0) || !std::isfinite(d.intensity) || !isFinite(d.colour))
      throw Error(d.loc, "environment_light colour and intensity must be finite and >= 0");
    Vec3 up = normalizeScaled(d.up);
    if (!isFinite(up) || length2(up) == 0) throw Error(d.loc, "environment_light up must be a non-zero direction");
    // The smallest rotation taking +y to up, then `rotate` about up.
    Vec3 y(0, 1, 0);
    if (up.y > 1 - 1e-7f) {
      e.ex_ = Vec3(1, 0, 0), e.ez_ = Vec3(0, 0, 1);
    } else if (up.y < -1 + 1e-7f) {
      e.ex_ = Vec3(1, 0, 0), e.ez_ = Vec3(0, 0, -1);
    } else {
      Vec3 k = normalize(cross(y, up));
      double a = std::acos(std::clamp(double(up.y), -1.0, 1.0));
      e.ex_ = normalize(rotateAbout(Vec3(1, 0, 0), k, a));
      e.ez_ = normalize(rotateAbout(Vec3(0, 0, 1), k, a));
    }
    e.ey_ = up;
    double rot = double(d.rotateDegrees) * kPi / 180;
    e.ex_ = normalize(rotateAbout(e.ex_, up, rot));
    e.ez_ = normalize(rotateAbout(e.ez_, up, rot));
    Color scale = d.colour * d.intensity;
    if (d.map) {
      e.mapPath_ = d.map->path;
      try {
        e.table_ = io::readImage(d.map->path, true, limits.maxTexturePixels);
      } catch (const io::ImageReadError& err) {
        switch (err.kind) {
          case io::ImageReadError::Kind::Open:
            throw Error(d.map->loc, "cannot open environment map " + quoteInput(d.map->path) + ": " + err.reason);
          case io::ImageReadError::Kind::TooLarge:
            throw Error(d.map->loc, fmt::format("environment map {} is {}x{} pixels, more than --max-texture-pixels ({})",
                                                quoteInput(d.map->path), err.width, err.height,
                                                limits.maxTexturePixels));
          case io::ImageReadError::Kind::Memory: throw Error(d.map->loc, err.reason);
          case io::ImageReadError::Kind::Decode: break;
        }
        throw Error(d.map->loc, "cannot read environment map " + quoteInput(d.map->path) + ": " + err.reason);
      }
      if (e.table_.width <= 0 || e.table_.height <= 0)
        throw Error(d.map->loc, "environment map " + quoteInput(d.map->path) + " is empty");
      for (Color& c : e.table_.pixels) {
        if (!isFinite(c))
          throw Error(d.map->loc, "environment map " + quoteInput(d.map->path) + " has non-finite pixels");
        c = vmax(c, Color(0)) * scale;  // negative radiance (EXR) is not light
      }
    } else {
      e.uniform_ = true;
      e.table_ = io::Image(1, 1);
      e.table_.pixels[0] = scale;
    }
    return e;
  }

  // sun_sky_light
  if (!(d.intensity >= 0) || !std::isfinite(d.intensity) || !isFinite(d.ground))
    throw Error(d.loc, "sun_sky_light intensity and ground must be finite and >= 0");
  Vec3 travel = normalizeScaled(d.sunDirection);
  if (!isFinite(travel) || !(travel.y < 0))
    throw Error(d.loc, "sun_sky_light: the sun must be above the horizon (direction needs y < 0)");
  e.sunTravel_ = travel;
  e.sky_.emplace(-travel, d.turbidity);
  const PreethamSky& sky = *e.sky_;
  // Bake the sky at pixel centres (kcd/m^2) and integrate its illuminance on a horizontal
  // surface; the sun adds its normal illuminance times cos(theta_s).
  io::Image t(kSkyWidth, kSkyHeight);
  double eh = 0;
  for (int j = 0; j < kSkyHeight / 2; ++j) {
    double v0 = double(j) / kSkyHeight, v1 = double(j + 1) / kSkyHeight;
    double omega = 2 * kPi / kSkyWidth * (std::cos(kPi * v0) - std::cos(kPi * v1));
    for (int i = 0; i < kSkyWidth; ++i) {
      Vec3 dir = e.direction((i + 0.5) / kSkyWidth, (j + 0.5) / kSkyHeight);
      Color L = sky.radiance(dir);
      t.at(i, j) = L;
      eh += lc::luminance(L) * double(dir.y) * omega;
    }
  }
  Color sunE = sky.sunIrradiance();
  eh += double(lc::luminance(sunE)) * double(-travel.y);
  // intensity 1: a white horizontal diffuse surface under sun and sky renders as 1, i.e.
  // its irradiance is pi in scene units.
  e.skyScale_ = float(kPi / eh) * d.intensity;
  e.ground_ = d.ground * d.intensity;
  for (int j = 0; j < kSkyHeight; ++j)
    for (int i = 0; i < kSkyWidth; ++i)
      t.at(i, j) = j < kSkyHeight / 2 ? t.at(i, j) * e.skyScale_ : e.ground_;
  e.table_ = std::move(t);
  e.hasSun_ = d.intensity > 0;
  e.sunIrradiance_ = sunE * e.skyScale_;
  return e;
}

Color Environment::radiance(const Vec3& d) const {
  if (sky_) {
    if (!(d.y > 0)) return ground_;
    Color L = sky_->radiance(d) * skyScale_;
    if (dot(d, -sunTravel_) >= std::cos(PreethamSky::kSunRadius)) L += sunIrradiance_ / PreethamSky::sunSolidAngle();
    return L;
  }
  if (uniform_) return table_.pixels[0];
  // Bilinear between pixel centres, wrapping in u, clamped in v.
  double u, v;
  coordinates(d, u, v);
  const int W = table_.width, H = table_.height;
  double x = u * W - 0.5, y = std::clamp(v * H - 0.5, 0.0, double(H - 1));
  double fx = std::floor(x), fy = std::floor(y);
  float ax = float(x - fx), ay = float(y - fy);
  int x0 = ((int(fx) % W) + W) % W, x1 = (x0 + 1) % W;
  int y0 = int(fy), y1 = std::min(y0 + 1, H - 1);
  Color top = table_.at(x0, y0) * (1 - ax) + table_.at(x1, y0) * ax;
  Color bottom = table_.at(x0, y1) * (1 - ax) + table_.at(x1, y1) * ax;
  return top * (1 - ay) + bottom * ay;
}

std::string Environment::describe() const {
  if (sky_)
    return fmt::format("sun_sky_light (Preetham sky, sun {:.1f} degrees above the horizon)",
                       90 - std::acos(std::clamp(-sunTravel_.y, -1.0f, 1.0f)) * 180 / kPi);
  if (uniform_) {
    Color c = table_.pixels[0];
    return fmt::format("environment_light (uniform, radiance ({:.4g}, {:.4g}, {:.4g}))", c.x, c.y, c.z);
  }
  return fmt::format("environment_light (map {}, {}x{})", quoteInput(mapPath_), table_.width, table_.height);
}

}  // namespace lc::scene
