#include "core/memory_budget.h"

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "core/error.h"

namespace lc {

namespace {

// The cgroup v2 (or v1) memory limit, when one is set.
std::optional<uint64_t> cgroupLimit() {
  for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    std::string s;
    if (!(in >> s) || s == "max") continue;
    if (auto v = parseBytes(s); v && *v > 0) return v;
  }
  return std::nullopt;
}

}  // namespace

uint64_t MemoryBudget::defaultLimit() {
  long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  uint64_t physical = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : (uint64_t(8) << 30);
  if (auto c = cgroupLimit(); c && *c < physical) physical = *c;
  return physical / 5 * 4;
}

bool MemoryBudget::tryReserve(uint64_t bytes) {
  uint64_t cur = used_.load(std::memory_order_relaxed);
  for (;;) {
    if (bytes > limit() || cur > limit() - bytes) return false;
    if (used_.compare_exchange_weak(cur, cur + bytes, std::memory_order_relaxed)) return true;
  }
}

void MemoryBudget::reserve(uint64_t bytes, std::string_view what) {
  if (!tryReserve(bytes)) throw Error(overBudget(bytes, what));
}

void MemoryBudget::release(uint64_t bytes) {
  uint64_t cur = used_.load(std::memory_order_relaxed);
  while (!used_.compare_exchange_weak(cur, cur - std::min(cur, bytes), std::memory_order_relaxed)) {
  }
}

std::string MemoryBudget::overBudget(uint64_t bytes, std::string_view what, uint64_t counted) const {
  const uint64_t rest = used() - std::min(used(), counted);
  std::string withRest;
  if (rest > bytes / 20) {
    const uint64_t total = bytes > std::numeric_limits<uint64_t>::max() - rest ? std::numeric_limits<uint64_t>::max()
                                                                                : rest + bytes;
    withRest = fmt::format(" ({} with what is already loaded)", formatBytes(total));
  }
  return fmt::format("{} need about {}{}, more than --max-memory ({})", what, formatBytes(bytes), withRest,
                     formatBytes(limit()));
}

MemoryBudget& processBudget() {
  static MemoryBudget budget;
  return budget;
}

std::string formatBytes(uint64_t bytes) {
  static const char* units[] = {"KB", "MB", "GB", "TB", "PB", "EB"};
  if (bytes < 1024) return fmt::format("{} bytes", bytes);
  double v = double(bytes);
  int u = -1;
  while (v >= 1024 && u < 5) {
    v /= 1024;
    ++u;
  }
  return fmt::format("{:.1f} {}", v, units[u]);
}

std::optional<uint64_t> parseBytes(std::string_view text) {
  std::string s(text);
  if (s.empty()) return std::nullopt;
  if (s.back() == 'B' || s.back() == 'b') s.pop_back();
  uint64_t mult = 1;
  if (!s.empty()) {
    switch (s.back()) {
      case 'K': case 'k': mult = uint64_t(1) << 10; break;
      case 'M': case 'm': mult = uint64_t(1) << 20; break;
      case 'G': case 'g': mult = uint64_t(1) << 30; break;
      case 'T': case 't': mult = uint64_t(1) << 40; break;
      default: break;
    }
    if (mult != 1) s.pop_back();
  }
  if (s.empty() || s.size() > 30) return std::nullopt;
  bool dot = false;
  for (char c : s) {
    if (c == '.' && !dot) dot = true;
    else if (c < '0' || c > '9') return std::nullopt;
  }
  if (s == ".") return std::nullopt;
  if (!dot) {
    uint64_t v = 0;
    for (char c : s) {
      if (v > (std::numeric_limits<uint64_t>::max() - uint64_t(c - '0')) / 10) return std::nullopt;
      v = v * 10 + uint64_t(c - '0');
    }
    if (v > std::numeric_limits<uint64_t>::max() / mult) return std::nullopt;
    return v * mult;
  }
  double d = std::stod(s) * double(mult);
  if (!(d >= 0) || d >= 1.8e19) return std::nullopt;
  return uint64_t(std::llround(d));
}

}  // namespace lc
