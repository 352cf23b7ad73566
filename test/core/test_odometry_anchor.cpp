// The chain tied to a globally referenced odometry (odometry_anchor.h): bounded by the
// odometry over a long run, as smooth as the chain from scan to scan, and its starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "cube_scan_matcher/core/odometry_anchor.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

namespace {

Eigen::Isometry3d poseAt(double x, double y, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotationFromRpy(0, 0, deg2rad(yaw_deg));
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

}  // namespace

TEST(OdometryAnchor, FollowsTheChainLocallyAndTheOdometryOverALongRun) {
  // A straight 2 km run, 2 m per scan. The chain has a 0.2 % scale error (it drifts 4 m), and
  // its motion's covariance says so (5 mm of noise and 4 mm of scale error per step); the
  // odometry is the truth plus a bounded, slowly changing offset of up to 0.5 m.
  OdometryAnchorSettings as;
  as.odometry_sigma_m = 0.5, as.odometry_sigma_rad = deg2rad(2.0);
  OdometryAnchor anchor(as);
  const Matrix6d motion = diagonalCovariance(std::hypot(0.005, 0.004), deg2rad(0.01));
  double worst_chain = 0.0, worst_anchor = 0.0, worst_step_error = 0.0;
  Eigen::Isometry3d last_anchor = Eigen::Isometry3d::Identity();
  for (int k = 0; k <= 1000; ++k) {
    const double x = 2.0 * k;
    const Eigen::Isometry3d truth = poseAt(x, 0, 0), chain = poseAt(1.002 * x, 0, 0);
    const Eigen::Isometry3d odom = poseAt(x + 0.5 * std::sin(k / 50.0), 0.5 * std::cos(k / 70.0), 0);
    const Eigen::Isometry3d a = anchor.add(chain, motion, odom);
    EXPECT_TRUE(a.matrix().allFinite());
    worst_chain = std::max(worst_chain, (chain.translation() - truth.translation()).norm());
    worst_anchor = std::max(worst_anchor, (a.translation() - truth.translation()).norm());
    if (k > 0) {
      // Each step differs from the true 2 m by far less than the odometry's offset changes.
      const double step = (a.translation() - last_anchor.translation()).norm();
      worst_step_error = std::max(worst_step_error, std::abs(step - 2.0));
    }
    last_anchor = a;
    EXPECT_GT(anchor.covariance().diagonal().minCoeff(), 0.0);
  }
  EXPECT_GT(worst_chain, 3.99);
  // Bounded near the odometry's own worst error (0.71 m; measured 0.82 m), and locally
  // smooth: a step off by at most 14 mm of its 2 m (measured 7 mm), where the chain's 4 m and
  // the odometry's wander would show.
  EXPECT_LT(worst_anchor, 1.0);
  EXPECT_LT(worst_step_error, 0.014);
}

TEST(OdometryAnchor, StartsAtTheOdometryOrAtTheChainAfterAGivenStart) {
  OdometryAnchor anchor{OdometryAnchorSettings{}};
  const Matrix6d motion = diagonalCovariance(0.01, 0.001);
  EXPECT_TRUE(anchor.add(poseAt(0, 0, 0), motion, poseAt(5, 1, 10)).isApprox(poseAt(5, 1, 10)));
  EXPECT_TRUE(anchor.covariance().isApprox(diagonalCovariance(0.5, deg2rad(2.0))));
  // Without odometry it predicts with the chain's motion alone.
  EXPECT_TRUE(anchor.add(poseAt(1, 0, 0), motion, std::nullopt).isApprox(poseAt(5, 1, 10) * poseAt(1, 0, 0)));
  anchor.reset(diagonalCovariance(0.1, 0.01));
  EXPECT_TRUE(anchor.add(poseAt(7, 7, 0), motion, poseAt(5, 1, 10)).isApprox(poseAt(7, 7, 0)));
  EXPECT_TRUE(anchor.covariance().isApprox(diagonalCovariance(0.1, 0.01)));
  OdometryAnchorSettings bad;
  bad.odometry_sigma_m = 0.0;
  EXPECT_THROW(OdometryAnchor{bad}, std::invalid_argument);
}
