#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

TEST(Pose, Eq2MatrixEqualsEigenComposition) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> a(-3.0, 3.0);
  for (int i = 0; i < 200; ++i) {
    const double roll = a(rng), pitch = a(rng) / 2, yaw = a(rng);
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    EXPECT_TRUE(rotationFromRpy(roll, pitch, yaw).isApprox(expected, 1e-12));
  }
}

TEST(Pose, YawRotatesXTowardsY) {
  const Eigen::Vector3d p = rotationFromRpy(0, 0, M_PI / 2) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(p.y(), 1.0, 1e-12);
}

TEST(Pose, RoundTrip) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> a(-3.1, 3.1), t(-50, 50);
  for (int i = 0; i < 200; ++i) {
    Pose6 p;
    p << t(rng), t(rng), t(rng), a(rng), a(rng) / 2.1, a(rng);
    const Pose6 q = isometryToPose(poseToIsometry(p));
    EXPECT_TRUE(q.isApprox(p, 1e-9)) << p.transpose() << "\n" << q.transpose();
  }
}

TEST(Pose, GimbalLockStillReproducesTheMatrix) {
  Pose6 p;
  p << 1, 2, 3, 0.3, M_PI / 2, -0.4;
  const Eigen::Isometry3d t = poseToIsometry(p);
  EXPECT_TRUE(poseToIsometry(isometryToPose(t)).isApprox(t, 1e-9));
}

TEST(Pose, WrapAngle) {
  EXPECT_NEAR(wrapAngle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrapAngle(-M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrapAngle(0.25), 0.25, 1e-15);
}

TEST(Pose, IsRigidTellsARotationFromAScaledOrMirroredOne) {
  Eigen::Isometry3d t = poseToIsometry((Pose6() << 1, -2, 3, 0.3, -0.2, 2.9).finished());
  EXPECT_TRUE(isRigid(t, 1e-12));
  Eigen::Isometry3d bent = t;
  bent.linear() *= 1.0 + 1e-5;  // a scaled rotation
  EXPECT_FALSE(isRigid(bent));
  EXPECT_TRUE(isRigid(bent, 1e-4));
  Eigen::Isometry3d mirrored = t;
  mirrored.linear().col(0) *= -1.0;  // orthonormal, det -1
  EXPECT_FALSE(isRigid(mirrored));
  t.translation().y() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(isRigid(t));
}
