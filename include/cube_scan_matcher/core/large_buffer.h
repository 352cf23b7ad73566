// Memory for the buffers that span a cube grid (V, the working copies of V): megabytes that are
// allocated again whenever a new reference outgrows them. Fresh memory costs one page fault per
// page at its first write, about 10 us per 4 kB page on a VM: a 15 MB grid costs some 40 ms
// to fault in. Allocated on 2 MB boundaries and advised as huge pages (Linux transparent huge
// pages in "madvise" or "always" mode), the same grid costs 8 faults. Only a hint to the
// kernel: without transparent huge pages, or elsewhere, the memory is ordinary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace cube_scan_matcher {

/// std::allocator's interface; blocks of kHugePage bytes or more are kHugePage-aligned, their
/// size rounded up to whole huge pages, and advised MADV_HUGEPAGE before anything is written.
template <typename T>
struct LargeBufferAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t{1} << 21;  // 2 MB

  LargeBufferAllocator() noexcept = default;
  template <typename U>
  LargeBufferAllocator(const LargeBufferAllocator<U>&) noexcept {}  // NOLINT: rebinding

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
    const std::size_t bytes = n * sizeof(T);
    void* p = nullptr;
    if (bytes >= kHugePage) {
      const std::size_t rounded = (bytes + kHugePage - 1) & ~(kHugePage - 1);
      p = std::aligned_alloc(kHugePage, rounded);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
      if (p) madvise(p, rounded, MADV_HUGEPAGE);  // a hint: its failure changes nothing
#endif
    } else {
      p = std::malloc(bytes == 0 ? 1 : bytes);
    }
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
};

template <typename T, typename U>
bool operator==(const LargeBufferAllocator<T>&, const LargeBufferAllocator<U>&) noexcept {
  return true;
}
template <typename T, typename U>
bool operator!=(const LargeBufferAllocator<T>&, const LargeBufferAllocator<U>&) noexcept {
  return false;
}

/// A vector whose storage comes from LargeBufferAllocator.
template <typename T>
using LargeBuffer = std::vector<T, LargeBufferAllocator<T>>;

}  // namespace cube_scan_matcher
