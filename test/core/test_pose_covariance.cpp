// The covariance helpers (pose_covariance.h): floors, rotation, the twist's covariance and
// the compounding along a chain, against closed forms and sampled poses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/pose_covariance.h"

using namespace cube_scan_matcher;

TEST(PoseCovariance, FloorsTheDiagonalAndRotatesBothBlocks) {
  Matrix6d c = Matrix6d::Zero();
  c(0, 0) = 1e-6;  // 1 mm
  c(1, 1) = 0.01;  // 10 cm
  c(0, 1) = c(1, 0) = 5e-5;
  const Matrix6d f = floorCovariance(c, 0.05, deg2rad(0.5));
  EXPECT_DOUBLE_EQ(f(0, 0), 0.0025);
  EXPECT_DOUBLE_EQ(f(1, 1), 0.01);
  EXPECT_DOUBLE_EQ(f(0, 1), 5e-5);
  EXPECT_DOUBLE_EQ(f(5, 5), deg2rad(0.5) * deg2rad(0.5));
  EXPECT_EQ(diagonalCovariance(0.05, 0.01), floorCovariance(Matrix6d::Zero(), 0.05, 0.01));
  // A 90 deg yaw swaps x and y, and roll and pitch.
  const Eigen::Matrix3d R = rotationFromRpy(0, 0, deg2rad(90));
  Matrix6d d = Matrix6d::Zero();
  d.diagonal() << 1, 2, 3, 4, 5, 6;
  const Matrix6d r = rotateCovariance(d, R);
  EXPECT_NEAR(r(0, 0), 2, 1e-12);
  EXPECT_NEAR(r(1, 1), 1, 1e-12);
  EXPECT_NEAR(r(3, 3), 5, 1e-12);
  EXPECT_NEAR(r(4, 4), 4, 1e-12);
  EXPECT_NEAR(r(5, 5), 6, 1e-12);
}

TEST(PoseCovariance, TwistCovarianceHasTheMeasurementAndTheMotionModel) {
  // Two pose errors of 5 cm / 0.5 deg over 0.5 s, and a velocity that changed by 0.2 m/s
  // along x and 0.1 rad/s about z since the previous twist.
  const Matrix6d pose = diagonalCovariance(0.05, deg2rad(0.5));
  Eigen::Matrix<double, 6, 1> change = Eigen::Matrix<double, 6, 1>::Zero();
  change(0) = 0.2, change(5) = -0.1;
  const Matrix6d c = twistCovariance(pose, 0.5, change);
  EXPECT_NEAR(c(0, 0), 2 * 0.0025 / 0.25 + 0.04, 1e-12);
  EXPECT_NEAR(c(1, 1), 2 * 0.0025 / 0.25, 1e-12);
  EXPECT_NEAR(c(5, 5), 2 * deg2rad(0.5) * deg2rad(0.5) / 0.25 + 0.01, 1e-12);
  EXPECT_EQ(c(0, 5), 0.0);
  // Off-diagonal terms of the pose covariance scale with it; a longer interval shrinks the
  // measurement's part, not the motion model's.
  Matrix6d corr = pose;
  corr(0, 1) = corr(1, 0) = 1e-4;
  EXPECT_NEAR(twistCovariance(corr, 0.5, change)(0, 1), 2 * 1e-4 / 0.25, 1e-15);
  EXPECT_NEAR(twistCovariance(pose, 2.0, change)(0, 0), 2 * 0.0025 / 4 + 0.04, 1e-12);
}

TEST(PoseCovariance, CompoundingCarriesTheKeyframesHeadingErrorThroughTheLeverArm) {
  // A keyframe known up to a 1 deg yaw error, an exact increment 10 m ahead along x: the pose
  // is off sideways by 10 m * 1 deg, correlated with the yaw.
  const double s = deg2rad(1.0);
  Matrix6d K = Matrix6d::Zero();
  K(5, 5) = s * s;
  const Matrix6d c = compoundCovariance(K, Matrix6d::Zero(), Eigen::Vector3d(10, 0, 0));
  EXPECT_NEAR(c(1, 1), 100 * s * s, 1e-15);
  EXPECT_NEAR(c(1, 5), 10 * s * s, 1e-15);
  EXPECT_NEAR(c(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(c(5, 5), s * s, 1e-15);
  // Without a lever arm the two covariances add.
  const Matrix6d a = diagonalCovariance(0.05, 0.01), b = diagonalCovariance(0.02, 0.03);
  EXPECT_TRUE(compoundCovariance(a, b, Eigen::Vector3d::Zero()).isApprox(a + b, 1e-12));
}

TEST(PoseCovariance, CompoundingMatchesSampledPoses) {
  // Monte Carlo: perturb a keyframe K and an increment I (its error in the keyframe's axes,
  // rotated into the map's as the nodelet does), compose P = K I, and compare the sample
  // covariance of P's error (dt = t' - t, dtheta = log(R' R^T)) with the formula.
  Eigen::Isometry3d K = Eigen::Isometry3d::Identity(), I = Eigen::Isometry3d::Identity();
  K.linear() = rotationFromRpy(0.05, -0.02, deg2rad(40));
  K.translation() = Eigen::Vector3d(5, -3, 1);
  I.linear() = rotationFromRpy(0.01, 0.02, deg2rad(-25));
  I.translation() = Eigen::Vector3d(4, 2, 0.3);
  Matrix6d CK = diagonalCovariance(0.03, deg2rad(0.8)), CI = diagonalCovariance(0.02, deg2rad(0.5));
  CK(0, 5) = CK(5, 0) = 0.3 * 0.03 * deg2rad(0.8);
  CI(1, 2) = CI(2, 1) = 0.2 * 0.02 * 0.02;
  const Matrix6d CI_map = rotateCovariance(CI, K.linear());
  const Matrix6d predicted =
      compoundCovariance(CK, CI_map, (K * I).translation() - K.translation());
  const Eigen::LLT<Matrix6d> LK(CK), LI(CI);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  auto perturb = [](const Eigen::Isometry3d& T, const Eigen::Matrix<double, 6, 1>& d) {
    Eigen::Isometry3d P = T;
    P.translation() += d.head<3>();
    const double angle = d.tail<3>().norm();
    if (angle > 0) P.linear() = Eigen::AngleAxisd(angle, d.tail<3>() / angle).toRotationMatrix() * T.linear();
    return P;
  };
  const Eigen::Isometry3d P = K * I;
  const int samples = 40000;
  Matrix6d sampled = Matrix6d::Zero();
  for (int k = 0; k < samples; ++k) {
    Eigen::Matrix<double, 6, 1> zk, zi;
    for (int j = 0; j < 6; ++j) zk(j) = n(rng), zi(j) = n(rng);
    const Eigen::Matrix<double, 6, 1> dk = LK.matrixL() * zk, di = LI.matrixL() * zi;
    // The increment's error in the keyframe's axes: I' = [t + dt, exp(dtheta) R] seen there.
    const Eigen::Isometry3d Pk = perturb(K, dk) * perturb(I, di);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = Pk.translation() - P.translation();
    const Eigen::AngleAxisd aa(Pk.linear() * P.linear().transpose());
    e.tail<3>() = aa.angle() * aa.axis();
    sampled += e * e.transpose() / samples;
  }
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      const double scale = std::sqrt(predicted(i, i) * predicted(j, j));
      EXPECT_NEAR(sampled(i, j), predicted(i, j), 0.04 * scale) << i << "," << j;
    }
  }
}
