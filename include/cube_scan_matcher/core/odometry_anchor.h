// Ties the registered chain to a globally referenced odometry (DGPS/IMU): a Kalman filter on
// SE(3) whose prediction is the chain's motion from one scan to the next (locally precise, but
// drifting without bound along the chain) and whose measurement is the odometry's pose
// (noisy, but its error bounded). The anchored pose is locally as smooth as the chain and,
// over a long run, stays within the odometry's error of the truth: the "map" of the REP-105
// role "anchored" (map -> odom pulled back towards the odometry instead of growing).
// ROS-free: the nodelet publishes it, the sequence benchmark measures it.
// Perturbations as in pose_covariance.h: t' = t + dt, R' = exp(dtheta) R, map axes [m, rad].
#pragma once

#include <optional>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/pose_covariance.h"

namespace cube_scan_matcher {

struct OdometryAnchorSettings {
  /// Standard deviation of the odometry's absolute error per position axis [m] and per
  /// rotation axis [rad] (the DGPS/IMU's accuracy, not its increment's).
  double odometry_sigma_m = 0.5;
  double odometry_sigma_rad = deg2rad(2.0);
};

/// Throws std::invalid_argument naming the bad setting (sigmas finite and > 0).
void validate(const OdometryAnchorSettings& settings);

class OdometryAnchor {
 public:
  explicit OdometryAnchor(const OdometryAnchorSettings& settings);  // validates

  /// One scan: `chain_pose` is the chain's pose of it (T_map_base), `motion_covariance` the
  /// covariance of the chain's motion since the previous scan given here (map axes), `odom`
  /// its odometry pose (T_odom_base) when known. The first scan after construction or reset()
  /// starts at the odometry pose (the chain's without odometry) with the odometry's
  /// covariance. Returns the anchored pose T_odom_base.
  Eigen::Isometry3d add(const Eigen::Isometry3d& chain_pose, const Matrix6d& motion_covariance,
                        const std::optional<Eigen::Isometry3d>& odom);

  /// The anchored pose's covariance after the last add() [m^2, rad^2], odometry frame axes.
  const Matrix6d& covariance() const { return covariance_; }
  /// The next add() starts afresh: at the odometry pose, or with `start_covariance` (map axes)
  /// at the chain's pose (a chain started at a given pose).
  void reset(const std::optional<Matrix6d>& start_covariance = std::nullopt);
  void setSettings(const OdometryAnchorSettings& settings);  // validates

 private:
  OdometryAnchorSettings settings_;
  std::optional<Eigen::Isometry3d> last_chain_;  ///< the chain's pose at the last add()
  std::optional<Matrix6d> start_covariance_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Matrix6d covariance_ = Matrix6d::Zero();
};

}  // namespace cube_scan_matcher
