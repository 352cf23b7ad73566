// Beyond the paper: keep only the points on surfaces the cloud samples densely at cube scale.
//
// Far from a scanner its samples thin out into separate rings and lines (on the ground at
// grazing angles, on a ceiling, on far walls): a surface there sets only some of the cubes it
// passes through, and which ones depends on where the samples fell. A second sweep taken from
// the same place samples the same spots, so its sparse samples fall in the same cubes; taken
// from anywhere else, they fall in other cubes of the same surface. J (section 2.2) therefore
// has a spike at "no motion" (the scan laid where the reference was taken) that can exceed J at
// the true motion where structure is weak (docs/experiments.md, "The no-motion maximum and
// dense_points"). Where a cube holds several samples the surface is sampled finer than the
// cubes, so its cubes are set whatever the sampling: counting only the scan points of such
// cubes in the coarse search removes the spike and keeps what constrains the pose.
#pragma once

#include <cstddef>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

struct DenseSamplingStats {
  std::size_t cubes = 0;        ///< cubes of edge `edge` holding points.
  std::size_t dense_cubes = 0;  ///< of which holding >= min_points points (kept).
  std::size_t kept = 0;         ///< points kept.
};

/// The points whose cube (edge `edge` [m] > 0, grid origin at 0) holds at least `min_points`
/// (>= 1) points of the cloud, in input order. O(n) with an open-addressing hash.
PointArray keepDenselySampled(const PointArray& points, double edge, int min_points,
                              DenseSamplingStats* stats = nullptr);

}  // namespace cube_scan_matcher
