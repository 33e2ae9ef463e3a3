// Progress of a long phase, reported by library code that does not know who listens.
// The caller hands a callback (`ProgressFn`, e.g. the CLI's progress bar); the library
// counts work done from any thread with `Progress::add`, and the callback is called with
// the fraction done, from one thread at a time, at most every 100 ms (and once at 1 when
// the phase ends). An empty callback costs one branch per `add`.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>

namespace lc {

using ProgressFn = std::function<void(double)>;

class Progress {
 public:
  Progress(const ProgressFn& fn, double total) : fn_(fn), total_(total > 0 ? total : 1) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  // `units` more done (any thread).
  void add(double units) {
    if (!fn_) return;
    double d = done_.load(std::memory_order_relaxed);
    while (!done_.compare_exchange_weak(d, d + units, std::memory_order_relaxed)) {
    }
    const int64_t now = nowMs();
    if (now - last_.load(std::memory_order_relaxed) < kIntervalMs) return;
    std::unique_lock<std::mutex> lock(mu_, std::try_to_lock);
    if (!lock.owns_lock() || finished_) return;  // another thread is reporting
    last_.store(now, std::memory_order_relaxed);
    fn_(std::clamp((d + units) / total_, 0.0, 1.0));
  }
  // The phase is over: the callback sees 1 (once).
  void finish() {
    if (!fn_) return;
    std::lock_guard<std::mutex> lock(mu_);
    if (finished_) return;
    finished_ = true;
    fn_(1.0);
  }

 private:
  static constexpr int64_t kIntervalMs = 100;
  static int64_t nowMs() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  const ProgressFn& fn_;
  double total_;
  std::atomic<double> done_{0};
  std::atomic<int64_t> last_{0};
  std::mutex mu_;
  bool finished_ = false;
};

}  // namespace lc
