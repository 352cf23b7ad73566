// De-skew: re-placing the points of a sweep taken while the robot moved.
//
// A tilting 2D scanner takes a sweep line by line over one to several seconds. Each point is
// placed in the base frame at the sweep's reference time `stamp` with the motion the caller
// believed (the odometry's, through tf) from its own time stamp + tau (tau <= 0 for a sweep
// stamped at its last line). With that motion and the true one both at constant velocity
// (screw motions T(tau) = exp(tau v), v a twist per second: v = log(increment) / interval),
// the truth of a point p placed with velocity v_placed is
//   p* = exp(tau v_true) exp(tau v_placed)^-1 p.
// A rigid sweep (no motion used to place it) has v_placed = 0.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

/// [translation part (m), rotation vector (rad)] of a rigid motion on SE(3).
using Twist = Eigen::Matrix<double, 6, 1>;

/// The SE(3) logarithm: the twist xi with exp(xi) = T (rotation angle in [0, pi]).
Twist logMotion(const Eigen::Isometry3d& T);
/// The SE(3) exponential: the screw motion of twist xi.
Eigen::Isometry3d expMotion(const Twist& xi);

/// The motion from time stamp to stamp + tau of a body moving at constant velocity with the
/// increment `motion` (T_prev_this) over `interval` [s]: exp(tau / interval * log(motion)).
Eigen::Isometry3d motionAt(const Twist& xi, double tau, double interval);

/// The constant velocity [twist per second] of the increment `motion` over `interval` [s]
/// (zero for interval <= 0).
Twist velocityOf(const Eigen::Isometry3d& motion, double interval);

/// The motion a registered pose implies over a sweep's own interval. The sweep's pose T
/// (scan -> reference) and the last known scan's pose (anchor = T_known_reference) span
/// `interval` [s]. When the known scan is the previous one, the sweep moved at the constant
/// velocity log(anchor T) / interval. When scans between were rejected (their poses are
/// predictions), one constant velocity over the whole span would lose the motion's shape (a
/// turn that reverses within it). With the odometry's motion over the span (`odom_span`) and
/// over the sweep's own interval `own` [s] (`odom_own`), the odometry's error over the span,
/// C = odom_span^-1 anchor T, is spread over the span at a constant rate, and the sweep's motion
/// is odom_own exp(own / interval log C): the odometry's shape, corrected.
struct SweepMotion {
  Eigen::Isometry3d anchor = Eigen::Isometry3d::Identity();
  double interval = 0.0;         ///< [s] from the known scan to the sweep's stamp
  bool odometry_shaped = false;  ///< odom_span, odom_own and own are set
  Eigen::Isometry3d odom_span = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d odom_own = Eigen::Isometry3d::Identity();
  double own = 0.0;  ///< [s] the sweep's own interval (since the previous scan)

  /// The sweep's velocity [twist per second] for its registered pose T.
  Twist velocity(const Eigen::Isometry3d& T) const;
};

/// Re-places `points` (base frame at the reference time) with time offsets `tau` [s] (same
/// size, relative to the reference time), placed with velocity `placed`, with velocity `truth`
/// instead (equation above). Points with equal tau share one transform (a 2D line's). Throws
/// std::invalid_argument on a size mismatch.
void deskew(PointArray& points, const std::vector<float>& tau, const Twist& placed,
            const Twist& truth);

}  // namespace cube_scan_matcher
