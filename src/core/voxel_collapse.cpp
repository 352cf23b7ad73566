#include "cube_scan_matcher/core/voxel_collapse.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace cube_scan_matcher {

namespace {
// 21 bits per axis: +-2^20 voxels around the origin.
std::uint64_t voxelKey(float x, float y, float z, float inv) {
  auto q = [inv](float v) {
    const double c = std::floor(double(v) * inv) + double(1 << 20);
    return std::uint64_t(std::min(std::max(c, 0.0), double((1 << 21) - 1)));
  };
  return q(x) | (q(y) << 21) | (q(z) << 42);
}
std::uint64_t mix(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
}
}  // namespace

PointArray collapseToVoxels(const PointArray& in, double voxel) {
  if (!(voxel > 0.0)) throw std::invalid_argument("collapse voxel must be > 0 m");
  const float inv = float(1.0 / voxel);
  std::size_t cap = 64;
  while (cap < 2 * in.size()) cap <<= 1;
  const std::uint64_t empty = ~std::uint64_t{0};
  std::vector<std::uint64_t> table(cap, empty);
  std::vector<std::uint32_t> keep;
  keep.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const std::uint64_t key = voxelKey(in.x[i], in.y[i], in.z[i], inv);
    for (std::size_t h = mix(key) & (cap - 1);; h = (h + 1) & (cap - 1)) {
      if (table[h] == key) break;
      if (table[h] == empty) {
        table[h] = key;
        keep.push_back(std::uint32_t(i));
        break;
      }
    }
  }
  PointArray out;
  out.reserve(keep.size());
  for (std::uint32_t i : keep) out.push_back(in.x[i], in.y[i], in.z[i]);
  return out;
}

}  // namespace cube_scan_matcher
