// De-skew: re-placing the points of a sweep taken while the robot moved.
//
// A tilting 2D scanner takes a sweep line by line over one to several seconds. Each point is
// placed in the base frame at the sweep's reference time `stamp` with the motion the caller
// believed (the odometry's, through tf) from its own time stamp + tau (tau <= 0 for a sweep
// stamped at its last line). With both that motion and the true one at constant velocity over
// the interval dt between the previous scan and this one (screw motions T = exp(tau / dt *
// xi), xi = log of the increment), the truth of a point p placed with `placed` is
//   p* = exp(tau/dt log(true)) exp(tau/dt log(placed))^-1 p,
// where `placed` and `true` are the scan's pose seen from the previous scan's (T_prev_this).
// A rigid sweep (no motion used to place it) has placed = identity.
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

/// Re-places `points` (base frame at the reference time) whose time offsets `tau` [s] (same
/// size, relative to the reference time) were placed with the increment `placed` over
/// `interval` [s], with the increment `truth` instead (equation above). Points with equal tau
/// share one transform (a 2D line's). Throws std::invalid_argument on a size mismatch or
/// interval <= 0.
void deskew(PointArray& points, const std::vector<float>& tau, double interval,
            const Eigen::Isometry3d& placed, const Eigen::Isometry3d& truth);

}  // namespace cube_scan_matcher
