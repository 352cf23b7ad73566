// Private to the core: buffers that are rebuilt for every new reference (grids, plane map,
// working copies, the keyframe submap) keep their memory. A buffer that must grow is allocated
// with a quarter of headroom, so that the next, slightly larger rebuild reuses it: fresh pages
// cost a fault each when first written (about 10 us on a VM), which made up most of a
// keyframe's rebuild in the rate benchmark (docs/experiments.md, the speed record). The
// grid-sized ones are LargeBuffers as well (core/large_buffer.h: huge pages where the kernel
// gives them).
#pragma once

#include <cstddef>
#include <vector>

#include "cube_scan_matcher/core/large_buffer.h"
#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

/// Makes room for n elements; the contents are dropped when the memory is not large enough
/// (callers assign or resize next).
template <typename T, typename Allocator>
void reserveForRebuild(std::vector<T, Allocator>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.clear();
  v.reserve(n + n / 4);
}

/// The same for a grid-sized LargeBuffer, with as much headroom again: a reference's extent
/// (and its grids' volume) jumps by 1.5-3x when a far outlier enters the submap, and a grid
/// that outgrows its buffer is written anew into fresh memory. Pages that are never written
/// cost nothing.
template <typename T>
void reserveForRebuild(LargeBuffer<T>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.clear();
  v.reserve(2 * n);
}

/// The same for the three arrays of a PointArray, which is emptied.
inline void clearForRebuild(PointArray& p, std::size_t n) {
  p.clear();
  reserveForRebuild(p.x, n);
  reserveForRebuild(p.y, n);
  reserveForRebuild(p.z, n);
}

}  // namespace cube_scan_matcher
