#include "app/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lc::app {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)), quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(double f) {
  if (quiet_) return;
  if (!started_) {
    started_ = true;
    start_ = std::chrono::steady_clock::now();
  }
  double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // Short renders print nothing; the final update only closes a bar that was shown.
  if (el < 1.0 && !shown_) return;
  shown_ = true;
  f = std::clamp(f, 0.0, 1.0);
  std::string eta = f > 0.01 ? formatSeconds(el * (1 - f) / f) : "?";
  if (tty_) {
    constexpr int kWidth = 30;
    int fill = int(f * kWidth);
    std::string bar(size_t(fill), '=');
    if (fill < kWidth) bar += '>';
    bar.resize(kWidth, ' ');
    fmt::print(stderr, "\r{} [{}] {:3d}%  {} elapsed, ETA {}   ", label_, bar, int(f * 100), formatSeconds(el), eta);
    std::fflush(stderr);
  } else {
    int decile = int(std::floor(f * 10));
    if (decile != lastDecile_) {
      lastDecile_ = decile;
      fmt::print(stderr, "{}: {:3d}% ({} elapsed, ETA {})\n", label_, decile * 10, formatSeconds(el), eta);
    }
  }
}

void ProgressBar::finish() {
  if (!quiet_ && shown_ && tty_) fmt::print(stderr, "\n");
}

std::string formatSeconds(double s) {
  if (!std::isfinite(s)) return "?";
  if (s < 1) return fmt::format("{:.0f} ms", s * 1000);
  if (s < 120) return fmt::format("{:.1f} s", s);
  if (s < 7200) return fmt::format("{:.0f} min {:.0f} s", std::floor(s / 60), std::fmod(s, 60));
  return fmt::format("{:.1f} h", s / 3600);
}

std::string formatCount(double n) {
  if (n >= 1e9) return fmt::format("{:.2f}G", n / 1e9);
  if (n >= 1e6) return fmt::format("{:.2f}M", n / 1e6);
  if (n >= 1e4) return fmt::format("{:.1f}k", n / 1e3);
  return fmt::format("{:.0f}", n);
}

}  // namespace lc::app
