// A progress bar with ETA on stderr: redrawn in place on a terminal, a few plain lines
// otherwise (logs, CI), nothing when quiet. It stays silent for the first second after its
// first update (the phase's start), so short phases print nothing. One bar per phase: scene
// phases, tree build, render and reference pixels each have their own.
#pragma once

#include <chrono>
#include <string>

namespace lc::app {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet);
  void update(double fraction);  // 0..1, from one thread
  void finish();

 private:
  std::string label_;
  bool quiet_, tty_, started_ = false, shown_ = false;
  int lastDecile_ = -1;
  std::chrono::steady_clock::time_point start_;
};

std::string formatSeconds(double s);
std::string formatCount(double n);  // 1234567 -> "1.23M"

}  // namespace lc::app
