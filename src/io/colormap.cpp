#include "io/colormap.h"

// stb_easy_font is a header of static functions; not all of them are used here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace lc::io {

namespace {

constexpr int kLineHeight = 12;     // stb_easy_font's line advance
constexpr size_t kMaxTextChars = 4096;

// stb_easy_font indexes its glyph table with (c - 32): anything outside printable ASCII
// would read out of bounds, so it is replaced.
std::string sanitize(const std::string& text) {
  std::string s = text.substr(0, std::min(text.size(), kMaxTextChars));
  for (char& c : s)
    if (c != '\n' && (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126)) c = '?';
  return s;
}

int lineCount(const std::string& s) { return 1 + int(std::count(s.begin(), s.end(), '\n')); }

int legendScale(int width) { return std::clamp(width / kHeatmapMinWidth, 1, 3); }

void fillRect(Image& img, int x0, int y0, int x1, int y1, Color c) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, img.width);
  y1 = std::min(y1, img.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) img.at(x, y) = c;
}

// Maps a value to [0,1] along the colour bar; NaN stays NaN.
struct Scale {
  double lo, hi;
  bool log, degenerate;
  Scale(float vmin, float vmax, bool logScale) : lo(vmin), hi(vmax), log(logScale) {
    if (log && !(lo > 0)) lo = hi / 1000.0;
    if (log && !(lo > 0)) log = false;  // vmax <= 0 too: no log scale is possible
    degenerate = !std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo);
  }
  double position(double v) const {
    if (std::isnan(v)) return v;
    if (degenerate) return 0;
    double t;
    if (log)
      t = v > lo ? std::log(v / lo) / std::log(hi / lo) : 0.0;
    else
      t = (v - lo) / (hi - lo);
    return std::clamp(t, 0.0, 1.0);
  }
  double valueAt(double t) const { return log ? lo * std::pow(hi / lo, t) : lo + t * (hi - lo); }
};

struct Layout {
  int scale, pad, titleH, barY, barH, tickLen, labelY, height;
};

Layout legendLayout(int width, const std::string& title) {
  Layout l{};
  l.scale = legendScale(width);
  const int s = l.scale;
  l.pad = 6 * s;
  l.titleH = title.empty() ? 0 : textHeight(title, s) + l.pad / 2;
  l.barY = l.pad + l.titleH;  // relative to the top of the strip
  l.barH = 14 * s;
  l.tickLen = 3 * s;
  l.labelY = l.barY + l.barH + l.tickLen + s;
  l.height = l.labelY + kLineHeight * s + l.pad / 2;
  return l;
}

}  // namespace

Color viridis(float tf) {
  // Degree-6 least-squares fit to matplotlib's viridis table (mattz's coefficients,
  // common in shaders); within about 0.01 of the table.
  double t = std::isnan(tf) ? 0.0 : std::clamp(double(tf), 0.0, 1.0);
  static constexpr double c[7][3] = {
      {0.2777273272234177, 0.005407344544966578, 0.3340998053353061},
      {0.1050930431085774, 1.404613529898575, 1.384590162594685},
      {-0.3308618287255563, 0.214847559468213, 0.09509516302823659},
      {-4.634230498983486, -5.799100973351585, -19.33244095627987},
      {6.228269936347081, 14.17993336680509, 56.69055260068105},
      {4.776384997670288, -13.74514537774601, -65.35303263337234},
      {-5.435455855934631, 4.645852612178535, 26.3124352495832},
  };
  Color out;
  for (int k = 0; k < 3; ++k) {
    double v = c[6][k];
    for (int i = 5; i >= 0; --i) v = c[i][k] + t * v;  // Horner
    out[k] = float(std::clamp(v, 0.0, 1.0));
  }
  return out;
}

int textWidth(const std::string& text, int scale) {
  std::string s = sanitize(text);
  return stb_easy_font_width(s.data()) * std::max(scale, 1);
}

int textHeight(const std::string& text, int scale) {
  return lineCount(sanitize(text)) * kLineHeight * std::max(scale, 1);
}

void drawText(Image& img, int x, int y, const std::string& text, Color color, int scale) {
  scale = std::max(scale, 1);
  std::string s = sanitize(text);
  if (s.empty()) return;
  // stb_easy_font emits quads of 4 vertices x 16 bytes (x, y, z floats, RGBA bytes);
  // a glyph needs at most a few hundred bytes.
  std::vector<char> buf(s.size() * 1024 + 64);
  int quads = stb_easy_font_print(0, 0, s.data(), nullptr, buf.data(), int(buf.size()));
  for (int q = 0; q < quads; ++q) {
    float minX = kInf, minY = kInf, maxX = -kInf, maxY = -kInf;
    for (int v = 0; v < 4; ++v) {
      float p[2];
      std::memcpy(p, buf.data() + size_t(q) * 64 + size_t(v) * 16, sizeof p);
      minX = std::min(minX, p[0]);
      maxX = std::max(maxX, p[0]);
      minY = std::min(minY, p[1]);
      maxY = std::max(maxY, p[1]);
    }
    // The quads are axis-aligned unit-wide segments on integer coordinates.
    fillRect(img, x + int(std::lround(minX)) * scale, y + int(std::lround(minY)) * scale,
             x + int(std::lround(maxX)) * scale, y + int(std::lround(maxY)) * scale, color);
  }
}

std::string heatmapTickLabel(double v) {
  char buf[32];
  // Whole numbers up to seven digits as they are: "25980", not "2.598e+04", which runs
  // into its neighbours on a 256-pixel bar.
  if (std::abs(v) >= 1e4 && std::abs(v) < 1e7)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.4g", v + 0.0);  // + 0.0 turns -0 into 0
  return buf;
}

int heatmapLegendHeight(int width, const std::string& title) { return legendLayout(width, title).height; }

Image heatmap(const std::vector<float>& values, int w, int h, float vmin, float vmax,
              const std::string& title, bool logScale) {
  if (w <= 0 || h <= 0 || values.size() != size_t(w) * size_t(h))
    throw Error("heatmap: " + std::to_string(values.size()) + " values for a " + std::to_string(w) +
                "x" + std::to_string(h) + " image");
  const int width = std::max(w, kHeatmapMinWidth);
  const Layout L = legendLayout(width, title);
  const Scale sc(vmin, vmax, logScale);
  Image out(width, h + L.height);
  for (Color& c : out.pixels) c = kHeatmapBackground;

  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double t = sc.position(values[size_t(y) * size_t(w) + size_t(x)]);
      out.at(x, y) = std::isnan(t) ? kHeatmapNanColor : viridis(float(t));
    }

  const int s = L.scale, top = h;
  if (!title.empty()) drawText(out, L.pad, top + L.pad, title, kHeatmapTextColor, s);

  // Tick values first: the bar's margins leave room for the end labels.
  const int nTicks = sc.degenerate ? 1 : 5;
  std::vector<double> tickT;
  std::vector<std::string> labels;
  int maxLabelW = 0;
  for (int k = 0; k < nTicks; ++k) {
    double t = nTicks == 1 ? 0.0 : double(k) / (nTicks - 1);
    tickT.push_back(t);
    labels.push_back(heatmapTickLabel(sc.degenerate ? double(vmin) : sc.valueAt(t)));
    maxLabelW = std::max(maxLabelW, textWidth(labels.back(), s));
  }
  const int margin = std::max(L.pad, maxLabelW / 2 + s);
  const int barX0 = margin, barX1 = std::max(width - margin, barX0 + 2);
  const int barW = barX1 - barX0;
  for (int x = barX0; x < barX1; ++x) {
    Color c = viridis(float(double(x - barX0) / double(barW - 1)));
    fillRect(out, x, top + L.barY, x + 1, top + L.barY + L.barH, c);
  }
  for (int k = 0; k < nTicks; ++k) {
    int px = barX0 + int(std::lround(tickT[size_t(k)] * (barW - 1)));
    int tx = std::clamp(px - s / 2, barX0, barX1 - s);
    fillRect(out, tx, top + L.barY + L.barH, tx + s, top + L.barY + L.barH + L.tickLen, kHeatmapTextColor);
    int lw = textWidth(labels[size_t(k)], s);
    int lx = std::clamp(px - lw / 2, 0, std::max(0, width - lw));
    drawText(out, lx, top + L.labelY, labels[size_t(k)], kHeatmapTextColor, s);
  }
  return out;
}

}  // namespace lc::io
