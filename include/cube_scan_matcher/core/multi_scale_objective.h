// Beyond the paper: the refine stage's objective, on the same scan as CoincidenceObjective but
// over several grids at once, and with rotations about a pivot:
//   F(q) = sum_k J_k(p) + w * J_E(p),   p = pose(q)
// J_k: coincident cubes on the fine grids (edge edge_fraction * E, origins shifted by k/K of a
// fine cube: less aliasing than one grid); J_E: on the coarse stage's E grid, weighted by w so
// that the refine cannot trade coarse agreement for a fine-level near-tie.
// The variable is q = [R c + t, roll, pitch, yaw] for a pivot c (the scan centroid by default):
// a step in an angle of q turns the points about c, so a pitch step does not also drag far
// points up and down (pitch and z decouple). pose(q) is the same pose of eq. (2): t = q_xyz - R c.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/vector6.h"

namespace cube_scan_matcher {

class MultiScaleObjective {
 public:
  /// Keeps the pointers: the objectives (bound to the scan by their setScan()) must outlive
  /// this. `coarse` is evaluated only when coarse_weight > 0. `pivot` [m] in the scan frame.
  MultiScaleObjective(std::vector<CoincidenceObjective*> fine, CoincidenceObjective* coarse,
                      double coarse_weight, const Eigen::Vector3d& pivot);

  /// F at the pivoted variable q (not at a pose).
  double operator()(const Vector6d& q);
  /// The pose of eq. (2) [m, rad] of the variable q, and back.
  Pose6 pose(const Vector6d& q) const;
  Vector6d variable(const Pose6& pose) const;
  /// The last evaluation went over all grids in one pass (see evaluateTogether).
  bool evaluatedTogether() const { return together_last_; }

 private:
  /// All grids in one pass over the scan, rotating each block of points once (the grids'
  /// rotations differ by powers of two): the same J as evaluating each, fewer operations. False
  /// (nothing evaluated) when the objectives do not qualify.
  bool evaluateTogether(const Pose6& p, int& fine_sum, int& coarse_j);

  std::vector<CoincidenceObjective*> fine_;
  CoincidenceObjective* coarse_;
  double coarse_weight_;
  Eigen::Vector3d pivot_;
  std::vector<CoincidenceObjective*> all_;  // fine_, then coarse_ when it is weighted
  // evaluateTogether's buffers, reused by every evaluation.
  std::vector<GridAffine> affines_;
  std::vector<float> scales_, ux_, uy_, uz_;
  std::vector<std::int32_t> idx_;
  bool together_last_ = false;
};

/// The centroid of the points [m] (double sums); zero for no point.
Eigen::Vector3d centroid(const PointArray& points);

}  // namespace cube_scan_matcher
