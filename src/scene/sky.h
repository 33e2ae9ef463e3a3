// The analytic daylight model of Preetham, Shirley and Smits, "A Practical Analytic Model
// for Daylight" (SIGGRAPH 1999): sky luminance and chromaticity from the Perez et al.
// distribution with turbidity-dependent coefficients (their Appendix A.2), and the sun's
// colour from the Rayleigh and aerosol (Angstrom) transmittance of their appendix, at three
// wavelengths (ozone, mixed gases and water vapour left out). Units: sky radiance in
// kcd/m^2 (Preetham's zenith luminance Y_z) as linear sRGB (Rec. 709 primaries, D65) whose
// luminance is Y; the sun as its illuminance at normal incidence in klux (the luminous solar
// constant, 128 klux, times the transmittance).
//
// The frame is y-up: directions with y > 0 are above the horizon. Valid for the sun above
// the horizon and turbidity in [2, 10].
#pragma once

#include "core/math.h"

namespace lc::scene {

class PreethamSky {
 public:
  // `toSun`: unit direction toward the sun (y > 0).
  PreethamSky(const Vec3& toSun, float turbidity);

  // Sky radiance (no sun) toward unit direction `d` above the horizon (d.y > 0), in
  // kcd/m^2; (0,0,0) at or below the horizon.
  Color radiance(const Vec3& d) const;
  // Luminance (kcd/m^2) toward `d`, as radiance()'s luminance.
  double luminance(const Vec3& d) const;
  // The sun's illuminance on a surface facing it (klux), RGB: 128 klux times the
  // transmittance at 650, 570 and 475 nm of the air mass at the sun's zenith angle.
  Color sunIrradiance() const { return sun_; }
  // The sun's angular radius (radians) and the solid angle of its disk.
  static constexpr float kSunRadius = 0.004654f;  // 0.2667 degrees
  static float sunSolidAngle() { return 2 * kPi * (1 - std::cos(kSunRadius)); }

  Vec3 toSun() const { return toSun_; }
  double zenithLuminance() const { return Yz_; }

 private:
  Vec3 toSun_;
  double thetaS_;
  double perezY_[5], perezX_[5], perezYc_[5];  // A..E for Y, x, y
  double Yz_, xz_, yz_;
  double normY_, normX_, normYc_;  // 1 / F(0, theta_s)
  Color sun_;
};

// xyY chromaticity and luminance to linear sRGB (Rec. 709, D65); negatives clamped to 0.
Color xyYToLinearSrgb(double x, double y, double Y);

}  // namespace lc::scene
