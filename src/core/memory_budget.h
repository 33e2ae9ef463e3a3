// --max-memory: one budget on the memory that input controls, counted before it is
// allocated, so that a hostile or oversized scene fails with a clear message instead of
// being killed by the system (or swapping it to a halt).
//
// What is counted, at the point where the count is first known (docs/ERRORS.md):
//   - .ray items (primitives, materials, area lights) and mesh vertices and triangles, as
//     the parser reads them and as an OBJ file's scan finds them;
//   - textures, from their header, before decoding; across all files together;
//   - lights (scene lights, object lights, VPLs) with their share of the light tree;
//   - the image buffers of a render.
// The per-item costs below are measured peak bytes (RSS of `info`/`render` on large
// generated inputs, commit of issue 23), rounded up; they include the Embree BVH and the
// light tree. The count is an estimate of the big consumers, not an allocator hook.
//
// Memory is a process-wide resource, so the budget is one process-wide counter
// (processBudget()); the CLI sets its limit once before loading.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace lc {

namespace memory_cost {
constexpr uint64_t kRayItem = 1280;     // one sphere{}/box{}/material/... of a .ray file
constexpr uint64_t kMeshVertex = 64;    // a mesh point with its normal and uv
constexpr uint64_t kMeshTriangle = 256; // a triangle: indices, Embree BVH, shading data
constexpr uint64_t kTexel = 16;         // float RGB texel plus the 8-bit decode buffer
constexpr uint64_t kLight = 320;        // a light, its cluster nodes and moments
constexpr uint64_t kPixel = 32;         // the colour, sample and AOV buffers of a render
}  // namespace memory_cost

class MemoryBudget {
 public:
  // The default limit: 80% of physical memory, or of the cgroup's memory.max when that is
  // lower (containers, CI runners).
  static uint64_t defaultLimit();

  explicit MemoryBudget(uint64_t limitBytes = defaultLimit()) : limit_(limitBytes) {}

  // Whether `bytes` more would fit (nothing counted).
  bool fits(uint64_t bytes) const { return bytes <= limit() && used() <= limit() - bytes; }
  // Counts `bytes` if they fit; false (and nothing counted) if not.
  bool tryReserve(uint64_t bytes);
  // Counts `bytes` or throws lc::Error with overBudget(bytes, what).
  void reserve(uint64_t bytes, std::string_view what);
  void release(uint64_t bytes);

  // "textures need about 3.9 GB (4.1 GB with what is already loaded), more than
  //  --max-memory (2.0 GB)". `bytes` is what `what` needs in all; `counted` the part of it
  // already in used() (a parser reporting its running total). The total is shown only when
  // the rest is more than a twentieth of it.
  std::string overBudget(uint64_t bytes, std::string_view what, uint64_t counted = 0) const;

  uint64_t used() const { return used_.load(std::memory_order_relaxed); }
  uint64_t limit() const { return limit_.load(std::memory_order_relaxed); }
  void setLimit(uint64_t bytes) { limit_.store(bytes, std::memory_order_relaxed); }
  void reset() { used_.store(0, std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> limit_;
  std::atomic<uint64_t> used_{0};
};

// The process's budget; its limit starts at defaultLimit().
MemoryBudget& processBudget();

// "1.5 GB", "512 MB", "900 bytes" (powers of 1024, one decimal).
std::string formatBytes(uint64_t bytes);
// "8G", "512M", "64k", "1.5G", "1000000" (bytes); suffixes K/M/G/T in powers of 1024, an
// optional trailing B. std::nullopt for anything else (negative, empty, junk, overflow).
std::optional<uint64_t> parseBytes(std::string_view text);

}  // namespace lc
