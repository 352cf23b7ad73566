// Six-parameter pose of the paper (eq. 2) and its conversions.
//
// Convention: a pose is [x0, y0, z0, roll α, pitch β, yaw γ] in metres and radians. It maps a
// point p* of the second (newer) scan into the frame of the first (reference) scan as
//   p = t + R p*,   R = Rz(γ) Ry(β) Rx(α)                                    (paper eq. 2)
// i.e. roll about X is applied first, then pitch about Y, then yaw about Z (fixed axes).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cube_scan_matcher {

/// [x, y, z, roll, pitch, yaw]: metres and radians.
using Pose6 = Eigen::Matrix<double, 6, 1>;

/// Rotation of eq. (2): Rz(yaw) * Ry(pitch) * Rx(roll), written out as in the paper.
Eigen::Matrix3d rotationFromRpy(double roll, double pitch, double yaw);

/// Rigid transform T (p = T p*) for a pose of eq. (2).
Eigen::Isometry3d poseToIsometry(const Pose6& pose);

/// Inverse of poseToIsometry. Pitch is returned in [-pi/2, pi/2]; at the gimbal lock
/// (|pitch| = 90 deg) roll is set to 0 and yaw absorbs the rest.
Pose6 isometryToPose(const Eigen::Isometry3d& transform);

/// Whether `transform` is a rigid motion: every entry finite and its linear part a rotation
/// (R^T R = I and det R = +1, each within `tolerance`). Products of many rigid transforms drift
/// from it by rounding; a pose chain that stays within 1e-6 of it is sound.
bool isRigid(const Eigen::Isometry3d& transform, double tolerance = 1e-6);

/// Wraps an angle to (-pi, pi].
double wrapAngle(double angle);

/// Whether two poses lie within `translation_m` [m] of each other and within `rotation_rad`
/// [rad] on each of roll, pitch and yaw (differences wrapped to (-pi, pi]).
bool posesWithin(const Pose6& a, const Pose6& b, double translation_m, double rotation_rad);

/// Degrees to radians.
constexpr double deg2rad(double deg) { return deg * 0.017453292519943295; }
/// Radians to degrees.
constexpr double rad2deg(double rad) { return rad * 57.29577951308232; }

}  // namespace cube_scan_matcher
