#include "cube_scan_matcher/core/pose_covariance.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace cube_scan_matcher {

Matrix6d floorCovariance(const Matrix6d& covariance, double sigma_m, double sigma_rad) {
  Matrix6d c = covariance;
  for (int i = 0; i < 6; ++i) {
    const double floor = i < 3 ? sigma_m * sigma_m : sigma_rad * sigma_rad;
    c(i, i) = std::max(c(i, i), floor);
  }
  return c;
}

double largestTranslationSigma(const Matrix6d& covariance) {
  const Eigen::Matrix3d c = covariance.topLeftCorner<3, 3>();
  const double var =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return std::sqrt(std::max(var, 0.0));
}

Matrix6d diagonalCovariance(double sigma_m, double sigma_rad) {
  return floorCovariance(Matrix6d::Zero(), sigma_m, sigma_rad);
}

Matrix6d rotateCovariance(const Matrix6d& covariance, const Eigen::Matrix3d& R_BA) {
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = R_BA;
  J.bottomRightCorner<3, 3>() = R_BA;
  return J * covariance * J.transpose();
}

Matrix6d compoundCovariance(const Matrix6d& keyframe, const Matrix6d& increment,
                            const Eigen::Vector3d& lever_arm) {
  Matrix6d J = Matrix6d::Identity();
  const Eigen::Vector3d& l = lever_arm;
  // -[l]x: the translation the keyframe's rotation error dtheta gives the pose, dtheta x l.
  J.topRightCorner<3, 3>() << 0.0, l.z(), -l.y(), -l.z(), 0.0, l.x(), l.y(), -l.x(), 0.0;
  const Matrix6d c = J * keyframe * J.transpose() + increment;
  return 0.5 * (c + c.transpose());
}

Matrix6d twistCovariance(const Matrix6d& pose_covariance, double interval,
                         const Eigen::Matrix<double, 6, 1>& velocity_change) {
  // Symmetric to the last bit (a rotated covariance is not, by rounding): filters check it.
  Matrix6d c = (pose_covariance + pose_covariance.transpose()) / (interval * interval);
  c.diagonal() += velocity_change.cwiseAbs2();
  return c;
}

}  // namespace cube_scan_matcher
