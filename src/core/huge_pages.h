// An allocator for the large arrays that cut selection walks at random (light-tree nodes,
// moments, lights): blocks of 4 MiB or more are aligned to 2 MiB and marked for transparent
// huge pages (madvise), so that one TLB entry covers 2 MiB instead of 4 KiB. A cut jumps
// between nodes megabytes apart, and each TLB miss is a page walk (two-level in a VM); where
// THP is off, or on other systems, this is plain aligned allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace lc {

// kUnwritten: resize() leaves new elements unwritten (below); false keeps std::vector's
// value-initialisation (HugeVector).
template <class T, bool kUnwritten = true>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;
  static constexpr size_t kThreshold = size_t(4) << 20;
  template <class U>
  struct rebind {
    using other = HugePageAllocator<U, kUnwritten>;
  };

  HugePageAllocator() noexcept = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U, kUnwritten>&) noexcept {}

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
  // resize() without a value leaves the new elements unwritten: the tree builders write
  // every element, in parallel, so the pages are first touched by the threads that fill
  // them rather than zeroed by one thread beforehand (1 GB of nodes at 10M lights:
  // 2.8 s, the page faults included, mostly serial). assign() and resize(n, value) are
  // unchanged.
  template <class U>
  void construct(U* p) noexcept(kUnwritten) {
    static_assert(std::is_trivially_destructible_v<U>, "BigVector holds plain data");
    if constexpr (kUnwritten)
      (void)p;
    else
      ::new (static_cast<void*>(p)) U();
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U, kUnwritten>&) const noexcept { return true; }
};

// A std::vector whose large blocks sit on huge pages.
template <class T>
using BigVector = std::vector<T, HugePageAllocator<T>>;
// The same with std::vector's value-initialisation kept (resize() writes T()), for arrays
// that code outside the tree builders grows.
template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T, false>>;

// Switches a BigVector's block between huge and 4 KiB pages (advice only). The light tree's
// layout fills its arrays in scattered order while it gives other large memory back: on
// 4 KiB pages memory grows with what is written rather than by 2 MiB at each first touch;
// afterwards moveToHugePages puts them on huge pages. (Marked for huge pages again, the
// block waited on khugepaged, which collapsed nothing before the render; MADV_COLLAPSE
// cost 1.7 s per 512 MB here.)
template <class T>
void useHugePages(BigVector<T>& v, bool on) {
#if defined(__linux__) && defined(MADV_HUGEPAGE) && defined(MADV_NOHUGEPAGE)
  constexpr size_t kPage = HugePageAllocator<T>::kHugePage;
  const size_t bytes = v.capacity() * sizeof(T);
  if (bytes >= HugePageAllocator<T>::kThreshold)
    madvise(v.data(), (bytes + kPage - 1) / kPage * kPage, on ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
#else
  (void)v;
  (void)on;
#endif
}

// Faults in the pages under [p, p + bytes) for writing with one system call (Linux 5.14+,
// MADV_POPULATE_WRITE; elsewhere nothing): each first touch of a page is otherwise a trap,
// and in a VM a costly one. Advice only.
inline void prefault(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr uintptr_t kPage = 4096;
  const uintptr_t a = reinterpret_cast<uintptr_t>(p) & ~(kPage - 1);
  const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + bytes + kPage - 1) & ~(kPage - 1);
  if (bytes > 0) madvise(reinterpret_cast<void*>(a), b - a, MADV_POPULATE_WRITE);
#else
  (void)p;
  (void)bytes;
#endif
}

// Moves a BigVector written on 4 KiB pages (useHugePages) onto a fresh block of huge
// pages: copied 2 MiB at a time, each piece of the old block given back to the system as
// soon as it is copied, so the memory in use grows by one piece, not by the array. The
// elements are unchanged. (The cost is a copy and the new pages' faults; MADV_COLLAPSE, which
// does the same in the kernel, took 1.7 s per 512 MB here.)
template <class T>
void moveToHugePages(BigVector<T>& v) {
  static_assert(std::is_trivially_copyable_v<T>, "BigVector holds plain data");
  constexpr size_t kPiece = HugePageAllocator<T>::kHugePage;
  const size_t bytes = v.size() * sizeof(T);
  if (bytes < HugePageAllocator<T>::kThreshold) return;
  BigVector<T> moved;
  moved.resize(v.size());  // unwritten: faulted in below, on huge pages
  char* to = reinterpret_cast<char*>(moved.data());
  char* from = reinterpret_cast<char*>(v.data());  // 2 MiB aligned (allocate)
  for (size_t at = 0; at < bytes; at += kPiece) {
    const size_t n = std::min(kPiece, bytes - at);
    std::memcpy(to + at, from + at, n);
#if defined(__linux__) && defined(MADV_DONTNEED)
    madvise(from + at, n, MADV_DONTNEED);
#endif
  }
  v.swap(moved);
}

}  // namespace lc
