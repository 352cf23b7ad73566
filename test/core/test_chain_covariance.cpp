// The covariance along a chain of keyframes (chain_covariance.h): the start, the compounding
// of accepted and rejected increments, the registration's scale and the systematic drift.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "cube_scan_matcher/core/chain_covariance.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

namespace {

Eigen::Isometry3d poseAt(double x, double y, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotationFromRpy(0, 0, deg2rad(yaw_deg));
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

/// A step of a chain: `pose` reached by `increment` from its keyframe.
OnlineStep chainStep(GateReason reason, const Eigen::Isometry3d& pose,
                     const Eigen::Isometry3d& increment, bool new_keyframe) {
  OnlineStep s;
  s.reason = reason;
  s.registered = reason != GateReason::FirstScan;
  s.accepted = reason == GateReason::Accepted;
  s.pose = pose;
  s.increment = increment;
  s.reference_updated = new_keyframe;
  return s;
}

}  // namespace


TEST(ChainCovariance, StartsAtTheFloorsAndCompoundsKeyframeByKeyframe) {
  ChainCovarianceSettings cs;
  cs.sigma_m = 0.01, cs.sigma_rad = deg2rad(0.1), cs.rejected_sigma_m = 0.1, cs.rejected_sigma_rad = deg2rad(1.0);
  cs.drift_fraction = 0.0;  // the random part alone
  ChainCovariance chain(cs);
  const Matrix6d floors = diagonalCovariance(0.01, deg2rad(0.1));
  const Eigen::Isometry3d I = poseAt(2, 0, 0);  // 2 m ahead, each step a new keyframe
  EXPECT_TRUE(chain.add(chainStep(GateReason::FirstScan, Eigen::Isometry3d::Identity(), I, true))
                  .pose.isApprox(floors));
  // An accepted step whose registration covariance is below the floors carries the floors,
  // compounded with the keyframe's through the 2 m lever arm.
  const StepCovariance c1 = chain.add(chainStep(GateReason::Accepted, I, I, true));
  EXPECT_TRUE(c1.pose.isApprox(compoundCovariance(floors, floors, Eigen::Vector3d(2, 0, 0))));
  EXPECT_TRUE(c1.increment.isApprox(floors));
  // A rejected one carries the rejected sigmas (the odometry's error over an increment).
  const StepCovariance c2 = chain.add(chainStep(GateReason::LowOverlap, I * I, I, false));
  EXPECT_TRUE(c2.pose.isApprox(
      compoundCovariance(c1.pose, diagonalCovariance(0.1, deg2rad(1.0)), Eigen::Vector3d(2, 0, 0))));
  // Standing still against the same keyframe the covariance does not grow.
  const StepCovariance c3 = chain.add(chainStep(GateReason::Accepted, I, Eigen::Isometry3d::Identity(), false));
  EXPECT_TRUE(c3.pose.isApprox(compoundCovariance(c1.pose, floors, Eigen::Vector3d::Zero())));
  EXPECT_TRUE(chain.add(chainStep(GateReason::Accepted, I, Eigen::Isometry3d::Identity(), false))
                  .pose.isApprox(c3.pose));
  // restart: the next first scan starts at the given covariance.
  chain.restart(Matrix6d(4.0 * floors));
  EXPECT_TRUE(chain.add(chainStep(GateReason::FirstScan, I, Eigen::Isometry3d::Identity(), true))
                  .pose.isApprox(4.0 * floors));
}

// A first scan whose grid could not be built (BadReference) is a chain start, not an increment
// from a keyframe that does not exist, and the first scan after it starts at the same covariance.
TEST(ChainCovariance, AFirstScanThatCouldNotBeTheReferenceStartsTheChain) {
  ChainCovariance chain(ChainCovarianceSettings{});
  const Matrix6d start = diagonalCovariance(0.3, deg2rad(2.0));
  chain.restart(start);
  const Eigen::Isometry3d far = poseAt(50, 20, 30);
  OnlineStep bad = chainStep(GateReason::BadReference, far, Eigen::Isometry3d::Identity(), false);
  bad.registered = false;
  EXPECT_TRUE(chain.add(bad).pose.isApprox(start));
  EXPECT_TRUE(chain.add(chainStep(GateReason::FirstScan, far, Eigen::Isometry3d::Identity(), true))
                  .pose.isApprox(start));
}

TEST(ChainCovariance, RegistrationScaleAndSystematicDrift) {
  ChainCovarianceSettings cs;
  cs.sigma_m = 1e-4, cs.sigma_rad = 1e-5, cs.registration_scale = 0.5;
  cs.drift_fraction = 0.001;
  ChainCovariance chain(cs);
  chain.add(chainStep(GateReason::FirstScan, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), true));
  OnlineStep s = chainStep(GateReason::Accepted, poseAt(10, 0, 0), poseAt(10, 0, 0), true);
  s.result.covariance = diagonalCovariance(0.02, 0.002);
  const StepCovariance c = chain.add(s);
  // The registration's sd halved, and the scale error along the 10 m displacement (x only).
  EXPECT_NEAR(c.increment(0, 0), 0.01 * 0.01, 1e-15);
  EXPECT_NEAR(c.increment(5, 5), 0.001 * 0.001, 1e-15);
  const Matrix6d random = compoundCovariance(diagonalCovariance(1e-4, 1e-5), c.increment,
                                             Eigen::Vector3d(10, 0, 0));
  EXPECT_NEAR(c.pose(0, 0) - random(0, 0), 0.01 * 0.01, 1e-12);
  EXPECT_NEAR(c.pose(1, 1) - random(1, 1), 0.0, 1e-15);
  EXPECT_NEAR(c.pose(0, 1) - random(0, 1), 0.0, 1e-15);
  EXPECT_NEAR(c.pose(3, 3) - random(3, 3), 0.0, 1e-15);
  // A chain that comes back to its start has no scale error left: the error moves with the
  // displacement.
  OnlineStep back = chainStep(GateReason::Accepted, poseAt(0, 0, 0), poseAt(-10, 0, 0), true);
  back.result.covariance = diagonalCovariance(0.02, 0.002);
  const StepCovariance b = chain.add(back);
  const Matrix6d random_b = compoundCovariance(random, b.increment, Eigen::Vector3d(-10, 0, 0));
  EXPECT_NEAR(b.pose(0, 0) - random_b(0, 0), 0.0, 1e-12);
  // At 6 m along x and 8 m along y from the start: f^2 d d^T, correlated.
  OnlineStep side = chainStep(GateReason::Accepted, poseAt(6, 8, 0), poseAt(6, 8, 0), true);
  side.result.covariance = diagonalCovariance(0.02, 0.002);
  const StepCovariance d = chain.add(side);
  const Matrix6d random_d = compoundCovariance(random_b, d.increment, Eigen::Vector3d(6, 8, 0));
  EXPECT_NEAR(d.pose(0, 1) - random_d(0, 1), 1e-6 * 48, 1e-12);
  EXPECT_NEAR(d.pose(1, 1) - random_d(1, 1), 1e-6 * 64, 1e-12);
}

TEST(ChainCovariance, RefusesSettingsOutOfRange) {
  ChainCovarianceSettings cs;
  EXPECT_NO_THROW(validate(cs));
  for (auto bad : {&ChainCovarianceSettings::sigma_m, &ChainCovarianceSettings::sigma_rad,
                   &ChainCovarianceSettings::registration_scale}) {
    ChainCovarianceSettings b;
    b.*bad = 0.0;
    EXPECT_THROW(validate(b), std::invalid_argument);
    b.*bad = std::nan("");
    EXPECT_THROW(validate(b), std::invalid_argument);
  }
  cs.registration_scale = 1.5;
  EXPECT_THROW(validate(cs), std::invalid_argument);
  cs = ChainCovarianceSettings{};
  cs.rejected_sigma_rad = 0.0;
  EXPECT_THROW(validate(cs), std::invalid_argument);
  cs = ChainCovarianceSettings{};
  cs.drift_fraction = -0.1;
  EXPECT_THROW(validate(cs), std::invalid_argument);
  cs = ChainCovarianceSettings{};
  cs.drift_fraction = std::nan("");
  EXPECT_THROW(ChainCovariance{cs}, std::invalid_argument);
}
