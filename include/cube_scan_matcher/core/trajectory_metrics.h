// Errors of an estimated trajectory against the truth, as odometry benchmarks report them:
// relative pose error over path segments (KITTI-style: % of the distance and deg/m), absolute
// trajectory error after a rigid alignment (Horn/Umeyama, no scale), and the drift while the
// robot stands still. Poses are T_world_base, one per scan, truth and estimate in step.
#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace cube_scan_matcher {

using Trajectory = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

/// Distance travelled along the truth up to each pose [m] (0 at the first).
std::vector<double> pathLengths(const Trajectory& truth);

struct RelativeError {
  double length = 0.0;             ///< [m] segment length asked for
  int segments = 0;                ///< segments evaluated (0: the path is shorter)
  double translation_pct = 0.0;    ///< mean |t_err| / travelled distance x 100
  double rotation_deg_per_m = 0.0; ///< mean rotation error angle / travelled distance
};
/// From every pose i to the first pose j at least `length` metres further along the truth:
/// E = (T_i^-1 T_j)_truth^-1 (T_i^-1 T_j)_estimate, averaged over i.
RelativeError relativePoseError(const Trajectory& truth, const Trajectory& estimate, double length);

/// RMS position error [m] after the rigid transform that best aligns the estimate's positions
/// to the truth's (least squares, Umeyama without scale).
double absoluteTrajectoryError(const Trajectory& truth, const Trajectory& estimate);

struct StationaryDrift {
  int segments = 0;         ///< runs of >= 2 scans where the truth does not move
  int scans = 0;            ///< scans in them
  double translation = 0.0; ///< [m] largest change of the estimate within a run
  double rotation_deg = 0.0;///< [deg] the same for the rotation angle
};
/// Over each run of scans whose true pose stays within `still_m` / `still_deg` of the run's
/// first, how far the estimate moves from its value at that first scan.
StationaryDrift stationaryDrift(const Trajectory& truth, const Trajectory& estimate,
                                double still_m = 1e-3, double still_deg = 0.01);

}  // namespace cube_scan_matcher
