// An allocator for the large arrays that cut selection walks at random (light-tree nodes,
// moments, lights): blocks of 4 MiB or more are aligned to 2 MiB and marked for transparent
// huge pages (madvise), so that one TLB entry covers 2 MiB instead of 4 KiB. A cut jumps
// between nodes megabytes apart, and each TLB miss is a page walk (two-level in a VM); where
// THP is off, or on other systems, this is plain aligned allocation.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace lc {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;
  static constexpr size_t kThreshold = size_t(4) << 20;

  HugePageAllocator() noexcept = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    size_t bytes = n * sizeof(T);
    if (bytes < kThreshold) {
      void* p = ::operator new(bytes, std::align_val_t(alignof(T) > 64 ? alignof(T) : 64));
      return static_cast<T*>(p);
    }
    size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure leaves 4 KiB pages
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) < kThreshold)
      ::operator delete(p, std::align_val_t(alignof(T) > 64 ? alignof(T) : 64));
    else
      std::free(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

// A std::vector whose large blocks sit on huge pages.
template <class T>
using BigVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace lc
