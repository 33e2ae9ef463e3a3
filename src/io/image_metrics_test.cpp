#include "io/image_metrics.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>  // header-only; used here only to check the JSON parses

#include <cmath>
#include <limits>

#include "core/error.h"

namespace lc::io {
namespace {

Image filled(int w, int h, Color c) {
  Image img(w, h);
  for (Color& p : img.pixels) p = c;
  return img;
}

TEST(ImageMetrics, IdenticalImages) {
  Image a = filled(4, 3, Color(0.2f, 0.5f, 0.9f));
  ImageMetrics m = compareImages(a, a);
  EXPECT_EQ(m.rmse, 0);
  EXPECT_EQ(m.relative_rmse, 0);
  EXPECT_EQ(m.mean_relative_error, 0);
  EXPECT_EQ(m.p99_relative_error, 0);
  EXPECT_EQ(m.fraction_over_threshold, 0);
  EXPECT_EQ(m.max_abs_error, 0);
  EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
  EXPECT_EQ(m.width, 4);
  EXPECT_EQ(m.height, 3);
  EXPECT_NEAR(m.floor, 0.01 * (0.2126 * 0.2 + 0.7152 * 0.5 + 0.0722 * 0.9), 1e-8);

  auto j = nlohmann::json::parse(metricsToJson(m));
  EXPECT_TRUE(j["psnr"].is_null());
  EXPECT_EQ(j["rmse"].get<double>(), 0.0);
  EXPECT_EQ(j["width"].get<int>(), 4);
}

// Four grey pixels of 0.5; one of them becomes 0.75 in the test image.
TEST(ImageMetrics, KnownPerturbation) {
  Image ref = filled(2, 2, Color(0.5f, 0.5f, 0.5f));
  Image test = ref;
  test.at(1, 0) = Color(0.75f, 0.75f, 0.75f);
  ImageMetrics m = compareImages(ref, test);
  EXPECT_NEAR(m.floor, 0.005, 1e-12);                // 1% of the mean luminance 0.5
  EXPECT_NEAR(m.mean_relative_error, 0.5 / 4, 1e-12);  // one pixel at 0.25/0.5
  EXPECT_NEAR(m.p99_relative_error, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(m.fraction_over_threshold, 0.25);
  EXPECT_NEAR(m.rmse, 0.125, 1e-12);                 // sqrt(3 * 0.25^2 / 12)
  EXPECT_NEAR(m.relative_rmse, 0.25, 1e-12);         // 0.125 / 0.5
  EXPECT_NEAR(m.psnr, 10 * std::log10(1 / 0.015625), 1e-9);  // peak 1: 18.06 dB
  EXPECT_DOUBLE_EQ(m.max_abs_error, 0.25);

  Image rel = relativeErrorImage(ref, test);
  EXPECT_NEAR(rel.at(1, 0).x, 0.5f, 1e-6f);
  EXPECT_EQ(rel.at(0, 0), Color(0, 0, 0));
  EXPECT_EQ(rel.at(1, 0).x, rel.at(1, 0).z);
}

TEST(ImageMetrics, FloorLimitsDarkPixelErrors) {
  // Mean luminance (1 + 0) / 2 = 0.5, floor 0.005: the black pixel's error is relative
  // to the floor, not to zero.
  Image ref(2, 1);
  ref.at(0, 0) = Color(1, 1, 1);
  ref.at(1, 0) = Color(0, 0, 0);
  Image test = ref;
  test.at(1, 0) = Color(0.001f, 0.001f, 0.001f);
  std::vector<float> e = relativeErrors(ref, test);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0], 0);
  EXPECT_NEAR(e[1], 0.001 / 0.005, 1e-6);
}

TEST(ImageMetrics, PsnrPeakFollowsHdrReference) {
  Image ref = filled(1, 2, Color(4, 4, 4));
  Image test = ref;
  test.at(0, 1) = Color(5, 4, 4);
  ImageMetrics m = compareImages(ref, test);
  double mse = 1.0 / 6;
  EXPECT_NEAR(m.psnr, 10 * std::log10(16 / mse), 1e-9);
  EXPECT_NEAR(m.relative_rmse, std::sqrt(mse) / 4, 1e-12);
}

TEST(ImageMetrics, PercentileAndThreshold) {
  // 100 pixels with relative errors 0, 0.001, ..., 0.099.
  Image ref = filled(10, 10, Color(1, 1, 1));
  Image test = ref;
  for (int i = 0; i < 100; ++i) {
    float v = 1.0f + 0.001f * float(i);
    test.pixels[size_t(i)] = Color(v, v, v);
  }
  ImageMetrics m = compareImages(ref, test, 0.0205);
  EXPECT_NEAR(m.p99_relative_error, 0.098, 1e-6);  // nearest rank 99 of 100
  EXPECT_DOUBLE_EQ(m.fraction_over_threshold, 0.79);    // errors 0.021 .. 0.099
  EXPECT_NEAR(m.mean_relative_error, 0.0495, 1e-6);
}

TEST(ImageMetrics, NonFiniteCountsAsInfinite) {
  Image ref = filled(2, 1, Color(1, 1, 1));
  Image test = ref;
  test.at(0, 0) = Color(std::numeric_limits<float>::quiet_NaN(), 1, 1);
  ImageMetrics m = compareImages(ref, test);
  EXPECT_TRUE(std::isinf(m.rmse));
  EXPECT_TRUE(std::isinf(m.max_abs_error));
  EXPECT_DOUBLE_EQ(m.fraction_over_threshold, 0.5);
  EXPECT_TRUE(std::isinf(m.p99_relative_error));
  auto j = nlohmann::json::parse(metricsToJson(m));  // still valid JSON
  EXPECT_TRUE(j["rmse"].is_null());
}

TEST(ImageMetrics, BlackReferenceUsesMinimumFloor) {
  Image ref = filled(2, 2, Color(0, 0, 0));
  ImageMetrics m = compareImages(ref, ref);
  EXPECT_EQ(m.floor, kMinRelativeFloor);
  EXPECT_EQ(m.relative_rmse, 0);
  Image test = filled(2, 2, Color(1e-6f, 1e-6f, 1e-6f));
  m = compareImages(ref, test);
  EXPECT_TRUE(std::isinf(m.relative_rmse));
  EXPECT_NEAR(m.mean_relative_error, 1.0, 1e-6);
}

TEST(ImageMetrics, MismatchedSizes) {
  try {
    compareImages(Image(2, 2), Image(2, 3));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot compare images of different sizes: reference is 2x2, test is 2x3");
  }
  EXPECT_THROW(relativeErrorImage(Image(1, 1), Image(2, 1)), Error);
  EXPECT_THROW(compareImages(Image(), Image()), Error);
}

TEST(ImageMetrics, JsonHasExactlyTheDocumentedKeys) {
  ImageMetrics m;
  m.rmse = 0.125;
  m.relative_rmse = 0.25;
  m.mean_relative_error = 1e-5;
  m.p99_relative_error = 0.5;
  m.fraction_over_threshold = 0.25;
  m.psnr = 18.0618;
  m.max_abs_error = 0.25;
  m.width = 640;
  m.height = 480;
  m.floor = 0.005;
  auto j = nlohmann::json::parse(metricsToJson(m));
  std::vector<std::string> keys;
  for (auto& [k, v] : j.items()) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, (std::vector<std::string>{"floor", "fraction_over_2pct", "fraction_over_threshold", "height",
                                            "max_abs_error", "mean_relative_error", "p99_relative_error", "psnr",
                                            "relative_rmse", "rmse", "threshold", "width"}));
  // The first name of the key stays, with the same value, for the scripts that read it.
  EXPECT_EQ(j["fraction_over_2pct"].get<double>(), 0.25);
  EXPECT_EQ(j["fraction_over_threshold"].get<double>(), 0.25);
  EXPECT_EQ(j["mean_relative_error"].get<double>(), 1e-5);  // round-trips exactly
  EXPECT_EQ(j["psnr"].get<double>(), 18.0618);
  EXPECT_EQ(j["height"].get<int>(), 480);
  EXPECT_TRUE(j["width"].is_number_integer());
}

}  // namespace
}  // namespace lc::io
