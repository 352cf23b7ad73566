// Errors of an estimated trajectory against the truth, as odometry benchmarks report them:
// relative pose error over path segments (KITTI-style: % of the distance and deg/m), absolute
// trajectory error after a rigid alignment (Horn/Umeyama, no scale), and the drift while the
// robot stands still. Poses are T_world_base, one per scan, truth and estimate in step.
#pragma once

#include <vector>

#include <Eigen/Core>
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

/// How well predicted covariances describe the errors they claim (filter consistency).
/// Errors per pose in the covariance's convention (pose_covariance.h): e = [t_est - t_true,
/// log(R_est R_true^T)] [m, rad], map axes. For a consistent 6-D Gaussian, about 68 % of an
/// axis's errors lie within 1 sd, 0.27 % beyond 3 sd, and the NEES e^T C^-1 e averages 6.
struct CovarianceConsistency {
  int poses = 0;                       ///< poses evaluated
  Eigen::Matrix<double, 6, 1> within1 = Eigen::Matrix<double, 6, 1>::Zero();  ///< share |e_i| <= sd_i
  Eigen::Matrix<double, 6, 1> beyond3 = Eigen::Matrix<double, 6, 1>::Zero();  ///< share |e_i| > 3 sd_i
  double nees_mean = 0.0, nees_median = 0.0;
};

/// Over the poses k with use[k] (all when `use` is empty): covariances[k] is estimate[k]'s
/// covariance [m^2, rad^2]. A pose whose covariance is not positive definite is skipped.
CovarianceConsistency covarianceConsistency(
    const Trajectory& truth, const Trajectory& estimate,
    const std::vector<Eigen::Matrix<double, 6, 6>>& covariances, const std::vector<bool>& use = {});

}  // namespace cube_scan_matcher
