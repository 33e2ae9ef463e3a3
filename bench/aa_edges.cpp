// aa_edges REF.exr TEST.exr [X0 Y0 [SIDE.png]]: how well TEST's edges match REF's (docs/LIGHTCUTS.md,
// "Adaptive antialiasing"). REF is a many-sample reference of the window of TEST that
// starts at (X0, Y0) (a centre crop rendered with a narrower field of view), written with
// --aov normal,depth. Edge pixels are those whose 3 x 3 neighbourhood in REF holds a
// geometric discontinuity (shading normals more than ~25 degrees apart, or depths more than
// 2% apart: a silhouette) or a luminance contrast (max - min) / max over 10%. Both images
// are compared as displayed: each channel sRGB-encoded (clamped to [0, 1]), then the
// luminance of that; the relative error is |test - ref| / max(ref, 0.01). SIDE.png: TEST's
// window and REF side by side (sRGB), edge pixels marked in a third panel.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "io/image.h"

using namespace lc;

int main(int argc, char** argv) {
  if (argc != 3 && argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: aa_edges REF.exr TEST.exr [X0 Y0 [SIDE.png]]\n");
    return 2;
  }
  const io::Image ref = io::readImage(argv[1]), test = io::readImage(argv[2]);
  const int x0 = argc >= 5 ? std::atoi(argv[3]) : 0, y0 = argc >= 5 ? std::atoi(argv[4]) : 0;
  const int w = ref.width, h = ref.height;
  if (x0 < 0 || y0 < 0 || x0 + w > test.width || y0 + h > test.height) {
    std::fprintf(stderr, "aa_edges: the reference's window does not fit in the test image\n");
    return 2;
  }
  int cw, ch;
  std::vector<float> nx = io::readExrChannel(argv[1], "normal.X", cw, ch);
  std::vector<float> ny = io::readExrChannel(argv[1], "normal.Y", cw, ch);
  std::vector<float> nz = io::readExrChannel(argv[1], "normal.Z", cw, ch);
  std::vector<float> depth = io::readExrChannel(argv[1], "depth.Z", cw, ch);
  auto display = [](const Color& c) {
    return luminance(Color(io::linearToSrgb(c.x), io::linearToSrgb(c.y), io::linearToSrgb(c.z)));
  };
  io::Image side(3 * w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      side.at(x, y) = test.at(x0 + x, y0 + y);
      side.at(w + x, y) = ref.at(x, y);
    }
  size_t edges = 0, under = 0, geometric = 0, geoUnder = 0, flat = 0, flatUnder = 0;
  // AA_EDGES_LIST=1: print each geometric edge pixel over 2%; =all: every edge pixel over 2%,
  // with its kind and (when TEST has --aov samples) the camera samples it took.
  const char* listEnv = std::getenv("AA_EDGES_LIST");
  const bool list = listEnv != nullptr, listAll = list && std::string(listEnv) == "all";
  std::vector<float> samples;
  try {
    int sw = 0, sh = 0;
    samples = io::readExrChannel(argv[2], "samples.Y", sw, sh);
  } catch (const std::exception&) {
  }
  double sum = 0;
  std::vector<double> errs;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      bool geo = false;
      float lo = kInf, hi = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int X = x + dx, Y = y + dy;
          if (X < 0 || Y < 0 || X >= w || Y >= h) continue;
          const size_t j = size_t(Y) * size_t(w) + size_t(X);
          const float l = luminance(ref.pixels[j]);
          lo = std::min(lo, l);
          hi = std::max(hi, l);
          const float d = nx[i] * nx[j] + ny[i] * ny[j] + nz[i] * nz[j];
          const bool finite = std::isfinite(depth[i]) && std::isfinite(depth[j]);
          if (finite != (std::isfinite(depth[i]) || std::isfinite(depth[j])) || d < 0.9f ||
              (finite && std::fabs(depth[i] - depth[j]) > 0.02f * std::max(depth[i], depth[j])))
            geo = true;
        }
      const bool contrast = hi > 0 && (hi - lo) / hi > 0.1f;
      const float r = display(ref.pixels[i]);
      const float t = display(test.at(x0 + x, y0 + y));
      const double e = std::fabs(double(t) - double(r)) / std::max(double(r), 0.01);
      if (!geo && !contrast) {  // the lighting's own error, for comparison
        ++flat;
        flatUnder += e < 0.02;
        continue;
      }
      ++edges;
      geometric += geo;
      side.at(2 * w + x, y) = e < 0.02 ? Color(0.1f, 0.3f, 0.1f) : Color(1, 0.1f, 0.1f);  // red: over 2%
      errs.push_back(e);
      sum += e;
      under += e < 0.02;
      geoUnder += geo && e < 0.02;
      if (list && (geo || listAll) && e >= 0.02)
        std::printf("over: %d %d ref %.4f test %.4f err %.2f%% %s samples %g\n", x, y, r, t, 100 * e,
                    geo ? "geometric" : "contrast",
                    samples.empty() ? 0.0 : double(samples[size_t(y0 + y) * size_t(test.width) + size_t(x0 + x)]));
    }
  std::sort(errs.begin(), errs.end());
  const double p99 = errs.empty() ? 0 : errs[std::min(errs.size() - 1, size_t(0.99 * double(errs.size())))];
  std::printf("edge pixels %zu of %d (%zu geometric); under 2%%: %.2f%%; mean %.2f%%, p95 %.2f%%, p99 %.2f%%\n", edges,
              w * h, geometric, edges ? 100.0 * double(under) / double(edges) : 100.0,
              edges ? 100 * sum / double(edges) : 0.0,
              errs.empty() ? 0.0 : 100 * errs[std::min(errs.size() - 1, size_t(0.95 * double(errs.size())))],
              100 * p99);
  std::printf("geometric edge pixels under 2%%: %.2f%%; contrast-only: %.2f%% of %zu\n",
              geometric ? 100.0 * double(geoUnder) / double(geometric) : 100.0,
              edges > geometric ? 100.0 * double(under - geoUnder) / double(edges - geometric) : 100.0, edges - geometric);
  std::printf("other pixels %zu; under 2%%: %.2f%%\n", flat, flat ? 100.0 * double(flatUnder) / double(flat) : 100.0);
  if (argc == 6) io::writeImage(argv[5], side, io::ToneMap::Srgb);
  return 0;
}
