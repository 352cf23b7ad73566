// Input filtering (paper section 3.2: no-return and max-range readings are not used).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

struct RangeFilterSettings {
  double min_range = 0.0;    ///< [m] points closer than this to `origin` are dropped (>= 0).
  double max_range = 1e9;    ///< [m] points farther than this are dropped (> min_range).
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< [m] sensor origin in the cloud frame.
};

/// What the filter kept and why it dropped the rest.
struct FilterStats {
  std::size_t input = 0;
  std::size_t non_finite = 0;    ///< NaN or inf in any coordinate.
  std::size_t out_of_range = 0;  ///< outside [min_range, max_range].
  std::size_t kept = 0;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const RangeFilterSettings& settings);

/// Appends the finite points of (x, y, z) within range to `out`. Works on any strided source,
/// so ROS and PCL adapters need not copy first. `stride` is in floats.
FilterStats appendFiltered(const float* x, const float* y, const float* z, std::size_t count,
                           std::size_t stride, const RangeFilterSettings& settings,
                           PointArray& out);

/// Filters a PointArray (convenience over appendFiltered).
PointArray filterPoints(const PointArray& in, const RangeFilterSettings& settings,
                        FilterStats* stats = nullptr);

/// The indices of the points of `in` that filterPoints keeps, in order: finite, within range,
/// and, when `times` is not empty, with a finite time. For values that travel with the points
/// (times, intensities): gather them with these. Throws std::invalid_argument if `times` is
/// neither empty nor one per point.
std::vector<std::uint32_t> keptIndices(const PointArray& in, const std::vector<float>& times,
                                       const RangeFilterSettings& settings,
                                       FilterStats* stats = nullptr);

/// The same with a time per point: the kept points' times go to `times_out` (a point whose time
/// is NaN or inf is dropped as non-finite). Throws std::invalid_argument on a size mismatch.
PointArray filterPoints(const PointArray& in, const std::vector<float>& times,
                        const RangeFilterSettings& settings, std::vector<float>& times_out,
                        FilterStats* stats = nullptr);

}  // namespace cube_scan_matcher
