// Online scan-to-previous-scan registration with a pose chain: the ROS-free heart of the
// nodelet. Each scan (in the robot's base frame) is registered to the current reference scan
// around the odometry increment, gated, chained onto the reference's pose, and becomes the
// next reference.
#pragma once

#include <deque>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

struct OnlineMatcherSettings {
  RegistrationSettings registration;
  GateSettings gate;
  /// After this many consecutive rejected scans the step reports `rejection_alarm`. >= 1.
  int max_consecutive_rejections = 5;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const OnlineMatcherSettings& settings);

/// What happened to one scan.
struct OnlineStep {
  GateReason reason = GateReason::FirstScan;
  bool registered = false;         ///< align() ran (a reference existed and the scan had points).
  bool accepted = false;           ///< the registration result gave the increment.
  bool odometry_guess = false;     ///< the guess came from odometry at both stamps (else identity).
  bool reference_updated = false;  ///< this scan is now the reference.
  bool time_reset = false;         ///< time went backwards: state was reset before this scan.
  bool rejection_alarm = false;    ///< consecutive rejections >= max_consecutive_rejections.
  int consecutive_rejections = 0;
  /// The gate's max_correction bounds were multiplied by this: the time since the reference
  /// in whole scan periods (the lower quartile of the last 16 intervals), in [1, 4]; the
  /// GNMM restart bounds are widened by the same factor for that registration. It is
  /// > 1 when scans were dropped or skipped: the odometry error grows with every increment
  /// the guess spans.
  double gate_scale = 1.0;
  RegistrationResult result;       ///< valid when registered.
  Pose6 guess = Pose6::Zero();     ///< scan -> reference guess [m, rad].
  Pose6 correction = Pose6::Zero();  ///< guess^-1 * result [m, rad] (zero if not registered).
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();  ///< scan -> reference, used.
  double interval = 0.0;           ///< [s] from the reference's stamp to this scan's (0 if first).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();       ///< T_map_base of this scan.
  std::string message;             ///< why, for logs.
};

class OnlineMatcher {
 public:
  explicit OnlineMatcher(const OnlineMatcherSettings& settings);  // validates

  /// `points`: the scan in the base frame at `stamp` [s] (finite points). `odom`: T_odom_base
  /// at `stamp` when known. The first scan's pose is its odometry pose (map = odom there), or
  /// identity without odometry. The guess is the odometry increment from the last reference
  /// that had odometry, carried over the accepted increments since (identity without
  /// odometry). A scan whose pose is unknown (no odometry and its registration rejected) does
  /// not become the reference, unless max_consecutive_rejections scans in a row were rejected.
  /// The gate's correction bounds and the search's restart bounds grow with the time since the
  /// reference, in whole scan periods: see OnlineStep::gate_scale.
  OnlineStep process(const PointArray& points, double stamp,
                     const std::optional<Eigen::Isometry3d>& odom);

  /// Forgets the reference, the pose chain and the rejection count.
  void reset();
  /// reset(), and the next scan starts the new chain at `pose` (T_map_base) instead of its
  /// odometry pose.
  void restartAt(const Eigen::Isometry3d& pose);
  /// Takes effect at the next scan. Validates, and rebuilds the current reference's grids with
  /// the new settings at once: throws std::invalid_argument (and keeps the old settings) when
  /// they cannot be built, e.g. a cube edge whose grid exceeds the memory cap.
  void setSettings(const OnlineMatcherSettings& settings);
  const OnlineMatcherSettings& settings() const { return settings_; }
  bool hasReference() const { return registration_.hasReference(); }
  /// Stamp of the last processed scan [s]; nullopt after reset.
  std::optional<double> lastStamp() const { return last_stamp_; }
  /// Pose of the last processed scan in the map frame.
  const Eigen::Isometry3d& lastPose() const { return last_pose_; }

 private:
  double gateScale(double stamp) const;
  OnlineMatcherSettings settings_;
  CubeRegistration registration_;
  PointArray reference_points_;  // kept to rebuild the grid when the cube edge changes
  Eigen::Isometry3d reference_pose_ = Eigen::Isometry3d::Identity();  // T_map_base(reference)
  std::optional<Eigen::Isometry3d> start_pose_;  // of the next first scan (restartAt)
  /// The last reference scan that had odometry: T_map_base and T_odom_base there. A scan with
  /// odometry is guessed from it, also when the references since then had none (a tf gap).
  struct OdometryAnchor {
    Eigen::Isometry3d pose, odom;
  };
  std::optional<OdometryAnchor> anchor_;
  bool reference_is_anchor_ = false;
  std::optional<double> last_stamp_;
  double reference_stamp_ = 0.0;
  std::deque<double> intervals_;  // [s] between consecutive scans, the last kIntervals
  static constexpr std::size_t kIntervals = 16;
  static constexpr double kMaxGateScale = 4.0;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  int consecutive_rejections_ = 0;
};

}  // namespace cube_scan_matcher
