#include "scene/sky.h"

#include <algorithm>
#include <cmath>

namespace lc::scene {

namespace {

// Perez et al.'s F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma).
double perez(const double* c, double cosTheta, double gamma, double cosGamma) {
  cosTheta = std::max(cosTheta, 1e-4);
  return (1 + c[0] * std::exp(c[1] / cosTheta)) * (1 + c[2] * std::exp(c[3] * gamma) + c[4] * cosGamma * cosGamma);
}

}  // namespace

Color xyYToLinearSrgb(double x, double y, double Y) {
  if (!(y > 0) || !(Y > 0)) return Color(0);
  double X = x * Y / y, Z = (1 - x - y) * Y / y;
  double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  return Color(float(std::max(0.0, r)), float(std::max(0.0, g)), float(std::max(0.0, b)));
}

PreethamSky::PreethamSky(const Vec3& toSun, float turbidity) : toSun_(normalize(toSun)) {
  const double T = turbidity;
  thetaS_ = std::acos(std::clamp(double(toSun_.y), -1.0, 1.0));
  const double ts = thetaS_;
  // Appendix A.2: the distribution coefficients, linear in T.
  const double Y[5] = {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251, 0.1206 * T - 2.5771,
                       -0.0670 * T + 0.3703};
  const double X[5] = {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125, -0.0641 * T - 0.8989,
                       -0.0033 * T + 0.0452};
  const double Yc[5] = {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102, -0.0441 * T - 1.6537,
                        -0.0109 * T + 0.0529};
  std::copy(Y, Y + 5, perezY_);
  std::copy(X, X + 5, perezX_);
  std::copy(Yc, Yc + 5, perezYc_);
  // Zenith luminance (kcd/m^2) and chromaticity.
  double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2 * ts);
  Yz_ = (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
  double t2 = ts * ts, t3 = t2 * ts;
  xz_ = T * T * (0.00166 * t3 - 0.00375 * t2 + 0.00209 * ts) +
        T * (-0.02903 * t3 + 0.06377 * t2 - 0.03202 * ts + 0.00394) +
        (0.11693 * t3 - 0.21196 * t2 + 0.06052 * ts + 0.25886);
  yz_ = T * T * (0.00275 * t3 - 0.00610 * t2 + 0.00317 * ts) +
        T * (-0.04214 * t3 + 0.08970 * t2 - 0.04153 * ts + 0.00516) +
        (0.15346 * t3 - 0.26756 * t2 + 0.06670 * ts + 0.26688);
  double cs = std::cos(ts);
  normY_ = 1 / perez(perezY_, 1, ts, cs);
  normX_ = 1 / perez(perezX_, 1, ts, cs);
  normYc_ = 1 / perez(perezYc_, 1, ts, cs);

  // The sun: relative optical air mass (Kasten's formula, as in Preetham's appendix), then
  // Rayleigh tau_R = exp(-0.008735 lambda^-4.08 m) and aerosol tau_a = exp(-beta lambda^-1.3 m)
  // with beta = 0.04608 T - 0.04586 (lambda in micrometres).
  double zenithDeg = ts * 180 / kPi;
  double m = 1 / (cs + 0.15 * std::pow(93.885 - zenithDeg, -1.253));
  double beta = 0.04608365 * T - 0.04586025;
  const double lambda[3] = {0.650, 0.570, 0.475};
  float rgb[3];
  for (int i = 0; i < 3; ++i) {
    double tauR = std::exp(-0.008735 * std::pow(lambda[i], -4.08) * m);
    double tauA = std::exp(-beta * std::pow(lambda[i], -1.3) * m);
    rgb[i] = float(128.0 * tauR * tauA);
  }
  sun_ = Color(rgb[0], rgb[1], rgb[2]);
}

double PreethamSky::luminance(const Vec3& d) const {
  if (!(d.y > 0)) return 0;
  double cosGamma = std::clamp(double(dot(d, toSun_)), -1.0, 1.0);
  double gamma = std::acos(cosGamma);
  return Yz_ * perez(perezY_, d.y, gamma, cosGamma) * normY_;
}

Color PreethamSky::radiance(const Vec3& d) const {
  if (!(d.y > 0)) return Color(0);
  double cosGamma = std::clamp(double(dot(d, toSun_)), -1.0, 1.0);
  double gamma = std::acos(cosGamma);
  double Y = Yz_ * perez(perezY_, d.y, gamma, cosGamma) * normY_;
  double x = xz_ * perez(perezX_, d.y, gamma, cosGamma) * normX_;
  double y = yz_ * perez(perezYc_, d.y, gamma, cosGamma) * normYc_;
  Color c = xyYToLinearSrgb(x, y, Y);
  // Rescale so that the colour's Rec. 709 luminance is Y exactly (clamping negatives may move it).
  float l = lc::luminance(c);
  return l > 0 ? c * float(Y / l) : Color(0);
}

}  // namespace lc::scene
