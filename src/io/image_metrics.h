// Image comparison for `lightcuts compare REF TEST` and the accuracy tests.
//
// Definitions (N pixels, lum = Rec. 709 luminance lc::luminance, in double precision):
//   floor               = 1% of the mean reference luminance. It keeps the relative error
//                         of dark pixels from exploding (Lightcuts' 2% threshold is a
//                         Weber-law bound and means nothing near black). When the reference
//                         is entirely black (mean <= 0, or not finite) the floor is
//                         kMinRelativeFloor.
//   rel(p)              = |lum(test_p) - lum(ref_p)| / max(lum(ref_p), floor)
//   mean_relative_error = mean of rel(p)
//   p99_relative_error  = 99th percentile of rel(p), nearest rank: the ceil(0.99 N)-th
//                         smallest value
//   fraction_over_threshold = fraction of pixels with rel(p) > relThreshold (0.02 by
//                         default); JSON also as fraction_over_2pct, its first name
//   rmse                = sqrt(mean over all pixels and the R, G, B channels of diff^2)
//   relative_rmse       = rmse / mean reference channel value (inf if that mean is 0 and
//                         rmse > 0, 0 if both are 0)
//   psnr                = 10 log10(peak^2 / mse) dB with peak = max(1, largest reference
//                         channel value): 1 for display-range images, the real peak for
//                         HDR ones. +inf for identical images.
//   max_abs_error       = largest |test - ref| over all channels
// A NaN or infinite difference counts as an infinite error (it is never skipped).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "io/image.h"

namespace lc::io {

constexpr double kMinRelativeFloor = 1e-6;

// rel(p) from the pixel's reference and test luminances and the floor (as defined above;
// the reference pixels of a render, render/reference_pixels.cpp, use it too).
inline double relativeError(double refLum, double testLum, double floor) {
  return std::fabs(testLum - refLum) / std::max(refLum, floor);
}

// The rank (1-based, in ascending order) of the 99th percentile of n >= 1 values, nearest
// rank: ceil(0.99 n), in integers so that 0.99 n does not round.
inline size_t p99Rank(size_t n) { return (99 * n + 99) / 100; }

struct ImageMetrics {
  double rmse = 0;
  double relative_rmse = 0;
  double mean_relative_error = 0;
  double p99_relative_error = 0;
  double fraction_over_threshold = 0;  // JSON: fraction_over_threshold, and fraction_over_2pct (the
                                       // first name, kept for scripts) whatever the threshold
  double threshold = 0.02;
  double psnr = 0;
  double max_abs_error = 0;
  int width = 0, height = 0;
  double floor = 0;
};

// Throws lc::Error when the sizes differ or the images are empty.
ImageMetrics compareImages(const Image& ref, const Image& test, double relThreshold = 0.02);

// rel(p) per pixel, top row first (e.g. the input of heatmap()).
std::vector<float> relativeErrors(const Image& ref, const Image& test);
// The same as a grey image (rel(p) in all three channels), e.g. to write as EXR.
Image relativeErrorImage(const Image& ref, const Image& test);

// One JSON object with exactly the keys rmse, relative_rmse, mean_relative_error,
// p99_relative_error, fraction_over_2pct, fraction_over_threshold, threshold, psnr, max_abs_error, width, height, floor.
// Non-finite values (psnr of identical images, an infinite error) are written as null,
// as JSON has no infinity. Doubles use the shortest form that reads back exactly.
std::string metricsToJson(const ImageMetrics& m);

}  // namespace lc::io
