#include "cube_scan_matcher/core/voxel_collapse.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "voxel_key.h"

namespace cube_scan_matcher {

PointArray collapseToVoxels(const PointArray& in, double voxel) {
  if (!(voxel > 0.0)) throw std::invalid_argument("collapse voxel must be > 0 m");
  const float inv = float(1.0 / voxel);
  // A tilting scanner's sweep has some 10 points per E/4 voxel: the map starts there. The
  // table and the kept indices are the thread's own from call to call: fresh ones of a few
  // hundred kB per scan would be faulted in page by page (core/large_buffer.h).
  thread_local detail::KeyIndex set;
  thread_local std::vector<std::uint32_t> keep;
  set.reset(in.size() / 8);
  keep.clear();
  keep.reserve(in.size() / 8);
  detail::forEachVoxelKey(in, inv, [&](std::size_t i, std::uint64_t key) {
    if (set.insert(key).second) keep.push_back(std::uint32_t(i));
  });
  PointArray out;
  out.reserve(keep.size());
  for (std::uint32_t i : keep) out.push_back(in.x[i], in.y[i], in.z[i]);
  return out;
}

bool voxelsNest(double coarse, double fine) {
  if (!(coarse > 0.0 && fine > 0.0)) return false;
  // The keys use float(1 / edge): floor(v * 2^k inv) / 2^k = floor(v * inv) when the fine
  // inverse is 2^k times the coarse one (k >= 0), and v * 2^k inv is exact.
  const float inv_coarse = float(1.0 / coarse), inv_fine = float(1.0 / fine);
  int exponent = 0;
  const float mantissa = std::frexp(inv_fine / inv_coarse, &exponent);
  return mantissa == 0.5f && exponent >= 1 && inv_fine == std::ldexp(inv_coarse, exponent - 1);
}

}  // namespace cube_scan_matcher
