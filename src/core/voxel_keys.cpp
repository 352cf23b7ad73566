// The voxel keys of a block of points, one function per instruction set (as the cube indices
// in cube_grid.cpp): the floor of eq.-(6)-style voxel coordinates dominates a scan's collapse
// and a plane map's build, and is scalar code on the baseline instruction set.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "simd_clones.h"
#include "voxel_key.h"

namespace cube_scan_matcher::detail {
namespace {

inline __attribute__((always_inline)) void voxelKeysBody(const float* x, const float* y,
                                                         const float* z, std::size_t n,
                                                         float inv, std::uint64_t* keys) {
  const double di = double(inv), offset = double(1 << 20), top = double((1 << 21) - 1);
  // voxelIndex() of each coordinate: the same exact operations, converted through int32 (the
  // index is in [0, 2^21 - 1]), which every vector instruction set converts to.
  auto index = [di, offset, top](float v) {
    const double c = std::floor(double(v) * di) + offset;
    return std::uint64_t(std::uint32_t(std::int32_t(std::min(std::max(0.0, c), top))));
  };
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = index(x[i]) | (index(y[i]) << 21) | (index(z[i]) << 42);
  }
}

CSM_SIMD_CLONES(voxelKeys,
                (const float* x, const float* y, const float* z, std::size_t n, float inv,
                 std::uint64_t* keys),
                (x, y, z, n, inv, keys))

}  // namespace

void voxelKeys(const float* x, const float* y, const float* z, std::size_t n, float inv,
               std::uint64_t* keys) {
  CSM_PICK_CLONE(voxelKeys, activeSimdPath())(x, y, z, n, inv, keys);
}

}  // namespace cube_scan_matcher::detail
