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

}  // namespace cube_scan_matcher
