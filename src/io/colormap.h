// Colour-mapped images with a legend: relative-error heatmaps, cut-size heatmaps.
//
// The map is viridis (perceptually uniform, readable in grey and by colour-blind
// readers), from a degree-6 polynomial fit. Heatmaps are display-referred: their values
// are already the colours to show, so write them with ToneMap::Clamp, not Srgb.
#pragma once

#include <string>
#include <vector>

#include "io/image.h"

namespace lc::io {

// Viridis at t in [0,1] (clamped; NaN reads as 0).
Color viridis(float t);

// Colour of NaN values in a heatmap.
constexpr Color kHeatmapNanColor{1.0f, 0.0f, 1.0f};
// Background of the legend strip and of any padding (dark grey).
constexpr Color kHeatmapBackground{0.08f, 0.08f, 0.08f};
constexpr Color kHeatmapTextColor{1.0f, 1.0f, 1.0f};
// Heatmaps narrower than this are padded on the right so the legend stays legible.
constexpr int kHeatmapMinWidth = 240;

// Maps values[y*w + x] (top row first) to viridis: vmin -> viridis(0), vmax -> viridis(1),
// values outside clamped. With logScale the position is log(v/vmin)/log(vmax/vmin); a
// vmin <= 0 is replaced by vmax/1000, and values <= vmin map to 0. vmax <= vmin maps
// everything to viridis(0).
// The result is max(w, kHeatmapMinWidth) wide: the map occupies x < w, y < h (top
// left, so out.at(x, y) is the value's pixel), then below it a legend strip of
// heatmapLegendHeight(width, title) rows: the title, a colour bar, ticks and labels.
// Throws lc::Error when values.size() != w*h or w, h <= 0.
Image heatmap(const std::vector<float>& values, int w, int h, float vmin, float vmax,
              const std::string& title, bool logScale = false);

// A legend's tick label: %.4g, but whole numbers from 10,000 to 9,999,999 in full.
std::string heatmapTickLabel(double v);

// Height of the legend strip heatmap() appends for an output `width` pixels wide.
int heatmapLegendHeight(int width, const std::string& title);

// Text with stb_easy_font (ASCII; other bytes are drawn as '?'), each font pixel a
// scale x scale block, the top-left of the text box at (x, y). Clipped to the image.
void drawText(Image& img, int x, int y, const std::string& text, Color color, int scale = 1);
// Width and height in pixels of drawText's output (12*scale per line).
int textWidth(const std::string& text, int scale = 1);
int textHeight(const std::string& text, int scale = 1);

}  // namespace lc::io
