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

}  // namespace cube_scan_matcher
