// The covariance of each pose an OnlineMatcher chains, in the map frame, as the sum of two
// parts:
//  - random: a scan's pose is its keyframe's pose times one increment (OnlineStep::increment),
//    so this part is the keyframe's compounded with the increment's through the lever arm
//    (compoundCovariance, pose_covariance.h); it grows like a random walk;
//  - systematic: a registration's small bias repeats from keyframe to keyframe, so its error
//    grows in proportion to the motion, not with the square root of the keyframes: a scale
//    error of the translations (sd drift_fraction) moves a pose along its displacement d from
//    the chain's start, covariance drift_fraction^2 d d^T.
// The defaults hold the errors of simulated runs within 3 sd at every keyframe, on worlds and
// seeds they were not chosen on (BENCHMARK.md, "Covariance along the chain").
// ROS-free: the nodelet publishes it, the sequence benchmark checks it against the truth (NEES
// and the share of errors within 1 and beyond 3 predicted sd per axis).
#pragma once

#include <optional>

#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/pose_covariance.h"

namespace cube_scan_matcher {

struct ChainCovarianceSettings {
  /// Floor of an accepted increment's standard deviations [m], [rad]: the registration's own
  /// covariance (plane_polish.h) is used above it; also the sd of a chain's start.
  double sigma_m = 0.001;
  double sigma_rad = deg2rad(0.002);
  /// Standard-deviation factor on the registration's own covariance within a chain, in
  /// (0, 1]: that covariance is calibrated on single pairs of every kind (big starts, little
  /// overlap), and between consecutive scans of a run it overstates the error.
  double registration_scale = 0.7;
  /// Standard deviations of an increment propagated by odometry (not accepted) [m], [rad]:
  /// the odometry's error over one increment. > 0.
  double rejected_sigma_m = 0.5;
  double rejected_sigma_rad = deg2rad(5.0);
  /// Systematic drift: sd of the translations' scale error [m/m]. >= 0.
  double drift_fraction = 0.001;
};

/// Throws std::invalid_argument naming the bad setting (sigmas > 0, registration_scale in
/// (0, 1], drift >= 0, all finite).
void validate(const ChainCovarianceSettings& settings);

/// One step's covariances [m^2, rad^2], order [x y z, rotation about x y z].
struct StepCovariance {
  Matrix6d pose = Matrix6d::Zero();  ///< of OnlineStep::pose, map axes
  /// Of the increment scan -> keyframe in the keyframe's axes: the registration's covariance
  /// floored when accepted, the scaled floors otherwise (the twist's measurement error).
  Matrix6d increment = Matrix6d::Zero();
  /// Of the motion from the previous step's pose to this one, map axes: this increment's
  /// error (and the previous one's, when both are seen from the same keyframe) and the
  /// systematic drift over the distance between them. The floors at a chain's first step.
  Matrix6d motion = Matrix6d::Zero();
};

class ChainCovariance {
 public:
  explicit ChainCovariance(const ChainCovarianceSettings& settings);  // validates

  /// The covariances of `step` (steps in the order OnlineMatcher::process returned them).
  /// A first scan (also one rejected as BadReference) starts the chain at the start covariance
  /// (restart's, else the floors); an
  /// accepted increment carries its registration's covariance floored, a rejected one the
  /// rejected sigmas; a step that made a new keyframe keeps its covariance for the
  /// steps that follow. Standing still (no new keyframe) the covariance does not grow.
  StepCovariance add(const OnlineStep& step);

  /// The next first scan starts at `start` (map axes) instead of the floors.
  void restart(const std::optional<Matrix6d>& start);
  /// Validates, then applies from the next step.
  void setSettings(const ChainCovarianceSettings& settings);
  const ChainCovarianceSettings& settings() const { return settings_; }

 private:
  ChainCovarianceSettings settings_;
  Matrix6d keyframe_ = Matrix6d::Zero();  ///< random part of the current keyframe's, map axes
  Eigen::Vector3d start_position_ = Eigen::Vector3d::Zero();  ///< the chain's first pose's [m]
  Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();  ///< the last step's [m]
  Matrix6d last_increment_ = Matrix6d::Zero();  ///< the last step's, map axes (0: a keyframe)
  std::optional<Matrix6d> start_;
};

}  // namespace cube_scan_matcher
