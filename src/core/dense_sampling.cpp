#include "cube_scan_matcher/core/dense_sampling.h"

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "voxel_key.h"

namespace cube_scan_matcher {

PointArray keepDenselySampled(const PointArray& points, double edge, int min_points,
                              DenseSamplingStats* stats) {
  if (!(edge > 0.0)) throw std::invalid_argument("dense sampling: cube edge must be > 0 m");
  if (min_points < 1) throw std::invalid_argument("dense sampling: min_points must be >= 1");
  const float inv = float(1.0 / edge);
  detail::KeyIndex set(points.size() / 8);
  std::vector<std::uint32_t> count;  // points per cube, by the cube's index
  std::vector<std::uint32_t> cube_of(points.size());
  detail::forEachVoxelKey(points, inv, [&](std::size_t i, std::uint64_t key) {
    const auto [index, added] = set.insert(key);
    if (added) count.push_back(0);
    cube_of[i] = index;
    ++count[index];
  });
  PointArray out;
  out.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (count[cube_of[i]] >= std::uint32_t(min_points)) out.push_back(points.x[i], points.y[i], points.z[i]);
  }
  std::size_t dense_cubes = 0;
  for (std::uint32_t c : count) dense_cubes += c >= std::uint32_t(min_points);
  if (stats) *stats = {count.size(), dense_cubes, out.size()};
  return out;
}

}  // namespace cube_scan_matcher
