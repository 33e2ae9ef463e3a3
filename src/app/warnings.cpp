#include "app/warnings.h"

#include <fmt/format.h>

#include <cmath>

namespace lc::app {

void printWarning(const std::string& message) { fmt::print(stderr, "lightcuts: warning: {}\n", message); }
void printHint(const std::string& message) { fmt::print(stderr, "lightcuts: hint: {}\n", message); }

double blackFraction(const io::Image& image, io::ToneMap tonemap, float exposure) {
  if (image.pixels.empty()) return 0;
  const float scale = std::exp2(exposure);
  size_t black = 0;
  for (const Color& c : image.pixels) {
    bool dark = true;
    for (int k = 0; k < 3 && dark; ++k) dark = io::quantize8(c[k], tonemap, scale) <= kBlackLevel;
    black += dark;
  }
  return double(black) / double(image.pixels.size());
}

std::string maxCutWarning(uint64_t cutsAtMaxCut, uint64_t shadingPoints, int maxCut) {
  if (shadingPoints == 0 || !(double(cutsAtMaxCut) > kMaxCutShare * double(shadingPoints))) return {};
  return fmt::format(
      "{:.1f}% of the cuts stopped at --max-cut {} before their error bound held: those pixels may be further "
      "from brute force than --error (raise --max-cut)",
      100.0 * double(cutsAtMaxCut) / double(shadingPoints), maxCut);
}

std::string blackImageWarning(const io::Image& image, io::ToneMap tonemap, float exposure, const RenderFacts& f) {
  double fraction = blackFraction(image, tonemap, exposure);
  if (fraction < kMostlyBlack) return "";
  std::string what = fraction >= 1 ? "the image is black" : fmt::format("the image is {:.1f}% black", 100 * fraction);
  if (f.lights == 0)
    return what + ": the scene has no lights";
  double hit = f.primaryRays ? double(f.shadingPoints) / double(f.primaryRays) : 1;
  if (f.shadingPoints == 0 || hit < 0.02) {
    if (f.cameraHitFraction >= 0.02)
      return what + fmt::format(": the surfaces the camera sees have black materials ({} shading points from {} camera "
                                "rays, though {:.0f}% of them hit a surface): a material's colours are 0 unless set; "
                                "give the objects one, e.g. material = {{ diffuse = (0.8, 0.8, 0.8); }}",
                                f.shadingPoints, f.primaryRays, 100 * f.cameraHitFraction);
    return what + fmt::format(": the camera sees almost nothing ({} shading points from {} camera rays); check the "
                              "camera's position and viewdir",
                              f.shadingPoints, f.primaryRays);
  }
  double blocked = f.shadowRays ? double(f.occludedRays) / double(f.shadowRays) : 0;
  if (blocked >= 0.5)
    return what + fmt::format(": everything is in shadow ({:.0f}% of the shadow rays found their light blocked); a "
                              "light may be inside or behind an object",
                              100 * blocked);
  return what + ": the light reaching the surfaces is too weak to show; check the lights' colours and their "
                "attenuation (constant, linear, quadratic coefficients against the scene's size), or raise --exposure";
}

std::string hintForError(const std::string& bare) {
  if (bare.rfind("unknown keyword ", 0) == 0)
    return "--lenient skips unknown keywords (and their values) with a warning instead of failing";
  return "";
}

}  // namespace lc::app
