// `lightcuts compare`: error metrics between a reference and a test image.
#include <fmt/format.h>

#include <filesystem>

#include "app/commands.h"
#include "app/warnings.h"
#include "core/file_util.h"
#include "io/colormap.h"
#include "io/image.h"
#include "io/image_metrics.h"

namespace lc::app {

namespace {

struct CompareArgs {
  std::string ref, test;
  bool json = false;
  std::string heatmap;
  double threshold = 0.02;
  float heatmapMax = 0.05f;
};

int runCompare(const CompareArgs& a) {
  // (comparing an image with itself is fine; overwriting either with the heatmap is not)
  checkDistinctPaths({{a.ref, "the reference image"}, {a.heatmap, "--heatmap"}});
  checkDistinctPaths({{a.test, "the test image"}, {a.heatmap, "--heatmap"}});
  if (!a.heatmap.empty()) checkWritable(a.heatmap);
  io::Image ref = io::readImage(a.ref), test = io::readImage(a.test);
  io::ImageMetrics m = io::compareImages(ref, test, a.threshold);
  // 8-bit files hold display-encoded values (render's default --tonemap srgb), not radiance.
  for (const std::string* p : {&a.ref, &a.test})
    if (fileExtension(*p) != "exr") {
      printWarning(quoteInput(*p) + " is an 8-bit image: its values are display-encoded (sRGB unless rendered "
                   "with --tonemap clamp), so the errors are not relative errors of radiance; compare .exr renders "
                   "for those");
      break;
    }
  if (!a.heatmap.empty()) {
    io::Image hm = io::heatmap(io::relativeErrors(ref, test), ref.width, ref.height, 0, a.heatmapMax,
                               fmt::format("relative error (0 .. {:g})", a.heatmapMax));
    io::writeImage(a.heatmap, hm);
  }
  if (a.json) {
    fmt::print("{}\n", io::metricsToJson(m));
    return 0;
  }
  fmt::print("size                   {}x{}\n", m.width, m.height);
  fmt::print("rmse                   {:.6g}\n", m.rmse);
  fmt::print("relative rmse          {:.4g}\n", m.relative_rmse);
  fmt::print("mean relative error    {:.4f}%\n", 100 * m.mean_relative_error);
  fmt::print("p99 relative error     {:.4f}%\n", 100 * m.p99_relative_error);
  fmt::print("pixels over {:g}%       {:.4f}%\n", 100 * a.threshold, 100 * m.fraction_over_threshold);
  fmt::print("max abs error          {:.6g}\n", m.max_abs_error);
  fmt::print("psnr                   {:.2f} dB\n", m.psnr);
  fmt::print("(relative error = |lum(test) - lum(ref)| / max(lum(ref), {:.4g}), the floor being 1% of the mean)\n", m.floor);
  return 0;
}

}  // namespace

void addCompareCommand(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* c = app.add_subcommand("compare", "Error metrics of TEST against the reference REF (RMSE, relative errors, PSNR)");
  c->add_option("ref", a->ref,
                "Reference image: .exr (linear, exact) or 8-bit (compared as stored, i.e. display-encoded; a warning "
                "says so)")
      ->required();
  c->add_option("test", a->test, "Test image, same size")->required();
  c->add_flag("--json", a->json, "Print the metrics as JSON");
  c->add_option("--heatmap", a->heatmap, "Write the per-pixel relative error, colour-mapped with a legend, to this PNG");
  const CompareArgs d;
  c->add_option("--heatmap-max", a->heatmapMax,
                fmt::format("Relative error at the top of the heatmap's scale; default {:g}", d.heatmapMax))
      ->check(CLI::Range(1e-6f, 1e6f));
  c->add_option("--threshold", a->threshold,
                fmt::format("Relative error counted by fraction_over_threshold (also written as fraction_over_2pct); "
                            "default {:g}", d.threshold))
      ->check(CLI::Range(0.0, 1e6));
  c->callback([a] {
    if (!parseOnly()) exitStatus() = runCompare(*a);
  });
}

}  // namespace lc::app
