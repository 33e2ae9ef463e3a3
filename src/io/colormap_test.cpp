#include "io/colormap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "test_util.h"

namespace lc::io {
namespace {

bool isText(const Color& c) { return c == kHeatmapTextColor; }

int countText(const Image& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += isText(img.at(x, y));
  return n;
}

TEST(Colormap, ViridisEndpoints) {
  // matplotlib's viridis starts at #440154 and ends at #fde725.
  Color lo = viridis(0), hi = viridis(1);
  EXPECT_NEAR(lo.x, 0x44 / 255.0f, 0.015f);
  EXPECT_NEAR(lo.y, 0x01 / 255.0f, 0.015f);
  EXPECT_NEAR(lo.z, 0x54 / 255.0f, 0.015f);
  EXPECT_NEAR(hi.x, 0xfd / 255.0f, 0.015f);
  EXPECT_NEAR(hi.y, 0xe7 / 255.0f, 0.015f);
  EXPECT_NEAR(hi.z, 0x25 / 255.0f, 0.015f);
  EXPECT_EQ(viridis(-3), lo);
  EXPECT_EQ(viridis(7), hi);
  EXPECT_EQ(viridis(std::numeric_limits<float>::quiet_NaN()), lo);
  // Luminance rises monotonically: the map reads correctly in grey.
  float prev = -1;
  for (int i = 0; i <= 100; ++i) {
    float l = luminance(viridis(float(i) / 100));
    EXPECT_GT(l, prev) << i;
    prev = l;
  }
}

TEST(Colormap, OutputSizeIncludesLegend) {
  std::vector<float> v(10 * 5, 0.5f);
  Image a = heatmap(v, 10, 5, 0, 1, "relative error");
  EXPECT_EQ(a.width, kHeatmapMinWidth);  // padded so the legend fits
  EXPECT_EQ(a.height, 5 + heatmapLegendHeight(a.width, "relative error"));
  EXPECT_GT(heatmapLegendHeight(a.width, "relative error"), 30);

  std::vector<float> big(600 * 4, 0.5f);
  Image b = heatmap(big, 600, 4, 0, 1, "");
  EXPECT_EQ(b.width, 600);
  EXPECT_EQ(b.height, 4 + heatmapLegendHeight(600, ""));
  // A title adds rows.
  EXPECT_GT(heatmapLegendHeight(600, "title"), heatmapLegendHeight(600, ""));
}

TEST(Colormap, MinAndMaxMapToTheEndpoints) {
  std::vector<float> v = {0.0f, 0.05f, 0.025f, -1.0f, 3.0f, std::numeric_limits<float>::quiet_NaN()};
  Image img = heatmap(v, 3, 2, 0.0f, 0.05f, "error");
  EXPECT_EQ(img.at(0, 0), viridis(0));
  EXPECT_EQ(img.at(1, 0), viridis(1));
  EXPECT_EQ(img.at(2, 0), viridis(0.5f));
  EXPECT_EQ(img.at(0, 1), viridis(0));  // clamped below
  EXPECT_EQ(img.at(1, 1), viridis(1));  // clamped above
  EXPECT_EQ(img.at(2, 1), kHeatmapNanColor);
  EXPECT_EQ(img.at(5, 0), kHeatmapBackground);  // padding right of the map
}

TEST(Colormap, LogScale) {
  std::vector<float> v = {1.0f, 10.0f, 100.0f, 0.0f};
  Image img = heatmap(v, 4, 1, 1.0f, 100.0f, "cut size", true);
  EXPECT_EQ(img.at(0, 0), viridis(0));
  EXPECT_EQ(img.at(1, 0), viridis(0.5f));
  EXPECT_EQ(img.at(2, 0), viridis(1));
  EXPECT_EQ(img.at(3, 0), viridis(0));  // <= vmin
}

TEST(Colormap, DegenerateRange) {
  std::vector<float> v = {3, 3, 3};
  Image img = heatmap(v, 3, 1, 3, 3, "all equal");
  EXPECT_EQ(img.at(0, 0), viridis(0));
  EXPECT_EQ(img.at(2, 0), viridis(0));
}

TEST(Colormap, LegendHasTitleBarAndLabels) {
  const int w = 300, h = 20;
  std::vector<float> v(size_t(w) * h, 0.01f);
  Image img = heatmap(v, w, h, 0.0f, 0.05f, "relative error");
  // No text inside the map itself.
  EXPECT_EQ(countText(img, 0, 0, w, h), 0);
  // Title rows: the first text line below the map.
  int titleBottom = h + textHeight("relative error", 1) + 6;
  EXPECT_GT(countText(img, 0, h, w, titleBottom), 20);
  // Labels at the bottom of the strip.
  EXPECT_GT(countText(img, 0, img.height - 16, w, img.height), 20);
  // The colour bar spans the map from its low to its high end.
  int barRow = -1;
  for (int y = h; y < img.height && barRow < 0; ++y)
    if (img.at(w / 2, y) != kHeatmapBackground && !isText(img.at(w / 2, y))) barRow = y;
  ASSERT_GE(barRow, 0);
  int first = 0, last = w - 1;
  while (img.at(first, barRow) == kHeatmapBackground) ++first;
  while (img.at(last, barRow) == kHeatmapBackground) --last;
  EXPECT_EQ(img.at(first, barRow), viridis(0));
  EXPECT_EQ(img.at(last, barRow), viridis(1));
}

// The labels of a large cut-size range (0 .. 25,980) do not run into each other on the
// narrowest legend.
TEST(Colormap, TickLabelsOfLargeValuesStayShort) {
  EXPECT_EQ(heatmapTickLabel(25980.4), "25980");
  EXPECT_EQ(heatmapTickLabel(12990), "12990");
  EXPECT_EQ(heatmapTickLabel(0.0125), "0.0125");
  EXPECT_EQ(heatmapTickLabel(456.5), "456.5");
  EXPECT_EQ(heatmapTickLabel(-0.0), "0");
  EXPECT_EQ(heatmapTickLabel(2.5e8), "2.5e+08");
  // heatmap() spaces five ticks over the bar, whose margins are half the widest label:
  // each label must be narrower than the space between ticks, with a gap.
  int widest = 0;
  for (int k = 0; k < 5; ++k) widest = std::max(widest, textWidth(heatmapTickLabel(25980.0 * k / 4)));
  const int spacing = (kHeatmapMinWidth - 2 * (widest / 2 + 1)) / 4;
  EXPECT_LE(widest + 6, spacing) << "widest label " << widest << " px, ticks " << spacing << " px apart";
}

TEST(Colormap, DrawText) {
  Image img(100, 30);
  drawText(img, 2, 2, "0.05", Color(1, 1, 1));
  int n = 0, minX = 100, maxX = -1, minY = 30, maxY = -1;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 100; ++x)
      if (img.at(x, y) == Color(1, 1, 1)) {
        ++n;
        minX = std::min(minX, x); maxX = std::max(maxX, x);
        minY = std::min(minY, y); maxY = std::max(maxY, y);
      }
  EXPECT_GT(n, 10);
  EXPECT_GE(minX, 2);
  EXPECT_LT(maxX, 2 + textWidth("0.05"));
  EXPECT_GE(minY, 2);
  EXPECT_LT(maxY, 2 + textHeight("0.05"));

  // Scale 2 covers about four times the pixels.
  Image big(200, 60);
  drawText(big, 0, 0, "0.05", Color(1, 1, 1), 2);
  int n2 = 0;
  for (const Color& c : big.pixels) n2 += c == Color(1, 1, 1);
  EXPECT_EQ(n2, 4 * n);

  // Clipped at the edges and safe with bytes outside printable ASCII.
  drawText(img, 95, 25, "clipped \xff\t\x7f text", Color(1, 0, 0), 3);
  drawText(img, -50, -50, "x", Color(1, 0, 0));
}

TEST(Colormap, BadSizeIsAnError) {
  EXPECT_THROW(heatmap({1, 2, 3}, 2, 2, 0, 1, ""), Error);
  EXPECT_THROW(heatmap({}, 0, 0, 0, 1, ""), Error);
}

TEST(Colormap, WritesAsPng) {
  lc::testing::TempDir dir;
  std::vector<float> v(64 * 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) v[size_t(y * 64 + x)] = 0.05f * float(x) / 63;
  Image img = heatmap(v, 64, 32, 0, 0.05f, "relative error (0 .. 5%)");
  writeImage(dir.file("h.png"), img);
  Image back = readImage(dir.file("h.png"));
  EXPECT_EQ(back.width, img.width);
  EXPECT_EQ(back.height, img.height);
}

}  // namespace
}  // namespace lc::io
