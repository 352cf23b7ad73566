// Trajectory errors against hand-computed cases: a straight run, a constant heading error,
// an offset and rotated copy (ATE 0 after alignment), standing still.
#include <gtest/gtest.h>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/trajectory_metrics.h"

using namespace cube_scan_matcher;

namespace {

Eigen::Isometry3d at(double x, double y, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0);
  T.linear() = rotationFromRpy(0, 0, deg2rad(yaw_deg));
  return T;
}

}  // namespace

TEST(TrajectoryMetrics, ScaleErrorGivesItsPercentOnEverySegment) {
  Trajectory truth, est;
  for (int k = 0; k <= 20; ++k) truth.push_back(at(k, 0, 0)), est.push_back(at(1.01 * k, 0, 0));
  EXPECT_DOUBLE_EQ(pathLengths(truth).back(), 20.0);
  const RelativeError r = relativePoseError(truth, est, 10.0);
  EXPECT_EQ(r.segments, 11);  // i = 0..10, j = i + 10
  EXPECT_NEAR(r.translation_pct, 1.0, 1e-9);
  EXPECT_NEAR(r.rotation_deg_per_m, 0.0, 1e-9);
  EXPECT_EQ(relativePoseError(truth, est, 50.0).segments, 0);
  EXPECT_THROW(relativePoseError(truth, Trajectory(3), 10.0), std::invalid_argument);
}

TEST(TrajectoryMetrics, HeadingDriftGivesDegreesPerMetre) {
  // Each 1 m step turns the estimate 0.01 deg more than the truth.
  Trajectory truth, est;
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  for (int k = 0; k <= 30; ++k) {
    truth.push_back(at(k, 0, 0));
    est.push_back(e);
    e = e * at(1, 0, 0.01);
  }
  const RelativeError r = relativePoseError(truth, est, 10.0);
  EXPECT_NEAR(r.rotation_deg_per_m, 0.01, 1e-9);
  EXPECT_GT(r.translation_pct, 0.0);
}

TEST(TrajectoryMetrics, AbsoluteErrorIsMeasuredAfterARigidAlignment) {
  Trajectory truth, est;
  const Eigen::Isometry3d offset = at(5, -3, 40);
  for (int k = 0; k < 10; ++k) {
    truth.push_back(at(k, 0.2 * k * k, 3.0 * k));
    est.push_back(offset * truth.back());
  }
  EXPECT_NEAR(absoluteTrajectoryError(truth, est), 0.0, 1e-9);
  est[4].translation().y() += 1.0;  // one position 1 m off: RMS of a rigid fit is below 1/sqrt(10)
  const double ate = absoluteTrajectoryError(truth, est);
  EXPECT_GT(ate, 0.2);
  EXPECT_LT(ate, 1.0 / std::sqrt(10.0) + 1e-9);
}

TEST(TrajectoryMetrics, StationaryDriftIsTheEstimatesMotionWhileTheTruthStands) {
  Trajectory truth, est;
  for (int k = 0; k < 3; ++k) truth.push_back(at(k, 0, 0)), est.push_back(at(k, 0, 0));
  for (int k = 0; k < 4; ++k) truth.push_back(at(3, 0, 0)), est.push_back(at(3 + 0.01 * k, 0, 0.1 * k));
  truth.push_back(at(3, 0, 30)), est.push_back(at(3.03, 0, 30));  // a turn on the spot ends it
  const StationaryDrift s = stationaryDrift(truth, est);
  EXPECT_EQ(s.segments, 1);
  EXPECT_EQ(s.scans, 4);
  EXPECT_NEAR(s.translation, 0.03, 1e-9);
  EXPECT_NEAR(s.rotation_deg, 0.3, 1e-9);
}
