#include "cube_scan_matcher/core/pose_covariance.h"

#include <algorithm>

namespace cube_scan_matcher {

Matrix6d floorCovariance(const Matrix6d& covariance, double sigma_m, double sigma_rad) {
  Matrix6d c = covariance;
  for (int i = 0; i < 6; ++i) {
    const double floor = i < 3 ? sigma_m * sigma_m : sigma_rad * sigma_rad;
    c(i, i) = std::max(c(i, i), floor);
  }
  return c;
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

}  // namespace cube_scan_matcher
