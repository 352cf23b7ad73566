// The covariance a registered pose carries: the registration's own (from the polish's
// point-to-plane problem, plane_polish.h) floored by configured standard deviations, and its
// propagation along a chain of keyframes. ROS-free; the nodelet publishes the result in
// PoseWithCovariance order [x y z, rotation about x y z] [m^2, rad^2].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cube_scan_matcher {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// `covariance` with each translation variance raised to at least sigma_m^2 and each rotation
/// variance to at least sigma_rad^2 (a diagonal is added: the result stays positive
/// semi-definite). A zero `covariance` (no estimate) gives the diagonal of the floors.
Matrix6d floorCovariance(const Matrix6d& covariance, double sigma_m, double sigma_rad);

/// The largest translation standard deviation of `covariance` [m], over every direction (the
/// square root of the largest eigenvalue of its translation block; 0 for a zero covariance).
double largestTranslationSigma(const Matrix6d& covariance);

/// A diagonal covariance of standard deviations sigma_m [m] and sigma_rad [rad].
Matrix6d diagonalCovariance(double sigma_m, double sigma_rad);

/// A covariance of [dt, dtheta] (left perturbation: t' = t + dt, R' = exp(dtheta) R) of a pose
/// expressed in frame A, re-expressed in frame B when B's axes are rotated by R_BA: both blocks
/// are rotated, C_B = diag(R, R) C_A diag(R, R)^T.
Matrix6d rotateCovariance(const Matrix6d& covariance, const Eigen::Matrix3d& R_BA);

/// The covariance of a pose P = K * I in the map frame from its keyframe's covariance
/// `keyframe` (map axes) and its increment's `increment` (already rotated into map axes,
/// rotateCovariance with R_map_keyframe), their errors independent. With the perturbation
/// t' = t + dt, R' = exp(dtheta) R of both: dP = [dt_K - [l]x dtheta_K + dt_I, dtheta_K +
/// dtheta_I], where l = t_P - t_K [m] is the lever arm (the increment's translation in map
/// axes): a heading error of the keyframe moves the pose by dtheta x l, so position variance
/// grows with the distance travelled from the keyframe, and along a chain of keyframes with
/// the square of the distance.
Matrix6d compoundCovariance(const Matrix6d& keyframe, const Matrix6d& increment,
                            const Eigen::Vector3d& lever_arm);

/// The variance put on every diagonal entry of a twist that is not known (a first scan, or a
/// scan whose registration was not accepted) [(m/s)^2, (rad/s)^2]: a 100 m/s or 100 rad/s
/// standard deviation, which a filter weighs as "no information" (rtabmap's odometry writes
/// 9999 there for the same reason). Never zero or negative: robot_localization reads |c| and
/// floors it at 1e-9, so 0 or -1 would claim a near-certain zero velocity.
constexpr double kUnknownTwistVariance = 1.0e4;

/// The covariance [(m/s)^2, (rad/s)^2] of a twist computed as the mean velocity over
/// `interval` [s] (> 0) of a motion between two registered poses, in the axes of
/// `pose_covariance` (one registered pose's covariance [m^2, rad^2] in the twist's axes):
///  - the measurement: two pose errors of that size over the interval, 2 C / interval^2
///    (made exactly symmetric);
///  - the motion model: the mean velocity stands for the velocity at the interval's end,
///    which differs from it by about the velocity's change over one interval; `velocity_change`
///    [m/s, rad/s] per axis (this twist minus the previous one; the twist itself when no earlier
///    one is known) enters squared on the diagonal.
Matrix6d twistCovariance(const Matrix6d& pose_covariance, double interval,
                         const Eigen::Matrix<double, 6, 1>& velocity_change);

}  // namespace cube_scan_matcher
