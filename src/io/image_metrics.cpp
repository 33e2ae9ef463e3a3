#include "io/image_metrics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace lc::io {

namespace {

constexpr double kInfD = std::numeric_limits<double>::infinity();

void checkSameSize(const Image& ref, const Image& test) {
  if (ref.width != test.width || ref.height != test.height)
    throw Error("cannot compare images of different sizes: reference is " + std::to_string(ref.width) +
                "x" + std::to_string(ref.height) + ", test is " + std::to_string(test.width) + "x" +
                std::to_string(test.height));
  if (ref.width <= 0 || ref.height <= 0 || ref.pixels.empty() || test.pixels.size() != ref.pixels.size())
    throw Error("cannot compare empty images");
}

// lc::luminance's Rec. 709 weights, evaluated in double so the metrics do not carry
// float rounding into values tests compare against hand computations.
double lum(const Color& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

double relativeFloor(const Image& ref) {
  double sum = 0;
  for (const Color& c : ref.pixels) sum += lum(c);
  double floor = 0.01 * sum / double(ref.pixels.size());
  return floor > 0 && std::isfinite(floor) ? floor : kMinRelativeFloor;
}

// Non-finite errors become +inf so they sort last and count as over any threshold.
double finiteOrInf(double e) { return std::isfinite(e) ? e : kInfD; }

std::vector<double> relErrors(const Image& ref, const Image& test, double floor) {
  std::vector<double> e(ref.pixels.size());
  for (size_t i = 0; i < e.size(); ++i) {
    double lr = lum(ref.pixels[i]), lt = lum(test.pixels[i]);
    e[i] = finiteOrInf(relativeError(lr, lt, floor));
  }
  return e;
}

std::string jsonNumber(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "null"; }

}  // namespace

ImageMetrics compareImages(const Image& ref, const Image& test, double relThreshold) {
  checkSameSize(ref, test);
  ImageMetrics m;
  m.width = ref.width;
  m.height = ref.height;
  m.floor = relativeFloor(ref);
  const size_t n = ref.pixels.size();

  double sumSq = 0, sumRef = 0, maxAbs = 0, maxRef = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      double r = ref.pixels[i][c], t = test.pixels[i][c];
      double d = finiteOrInf(std::fabs(t - r));
      sumSq += d * d;
      maxAbs = std::max(maxAbs, d);
      sumRef += r;
      if (std::isfinite(r)) maxRef = std::max(maxRef, r);
    }
  const double mse = sumSq / double(3 * n);
  m.rmse = std::sqrt(mse);
  const double meanRef = sumRef / double(3 * n);
  m.relative_rmse = meanRef > 0 ? m.rmse / meanRef : (m.rmse == 0 ? 0 : kInfD);
  const double peak = std::max(1.0, maxRef);
  m.psnr = mse == 0 ? kInfD : 10.0 * std::log10(peak * peak / mse);
  m.max_abs_error = maxAbs;

  std::vector<double> e = relErrors(ref, test, m.floor);
  double sumRel = 0;
  size_t over = 0;
  for (double v : e) {
    sumRel += v;
    if (v > relThreshold) ++over;
  }
  m.mean_relative_error = sumRel / double(n);
  m.fraction_over_threshold = double(over) / double(n);
  m.threshold = relThreshold;
  // Nearest rank: the ceil(0.99 n)-th smallest.
  size_t rank = p99Rank(n);
  std::nth_element(e.begin(), e.begin() + long(rank - 1), e.end());
  m.p99_relative_error = e[rank - 1];
  return m;
}

std::vector<float> relativeErrors(const Image& ref, const Image& test) {
  checkSameSize(ref, test);
  std::vector<double> e = relErrors(ref, test, relativeFloor(ref));
  return std::vector<float>(e.begin(), e.end());
}

Image relativeErrorImage(const Image& ref, const Image& test) {
  std::vector<float> e = relativeErrors(ref, test);
  Image img(ref.width, ref.height);
  for (size_t i = 0; i < e.size(); ++i) img.pixels[i] = Color(e[i], e[i], e[i]);
  return img;
}

std::string metricsToJson(const ImageMetrics& m) {
  return fmt::format(
      "{{\"rmse\": {}, \"relative_rmse\": {}, \"mean_relative_error\": {}, \"p99_relative_error\": {}, "
      "\"fraction_over_2pct\": {}, \"fraction_over_threshold\": {}, \"threshold\": {}, \"psnr\": {}, \"max_abs_error\": {}, \"width\": {}, \"height\": {}, "
      "\"floor\": {}}}",
      jsonNumber(m.rmse), jsonNumber(m.relative_rmse), jsonNumber(m.mean_relative_error),
      jsonNumber(m.p99_relative_error), jsonNumber(m.fraction_over_threshold),
      jsonNumber(m.fraction_over_threshold), jsonNumber(m.threshold), jsonNumber(m.psnr),
      jsonNumber(m.max_abs_error), m.width, m.height, jsonNumber(m.floor));
}

}  // namespace lc::io
