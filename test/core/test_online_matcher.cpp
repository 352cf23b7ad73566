// OnlineMatcher (the nodelet's core) without ROS: chaining, resets, rejections.
#include <gtest/gtest.h>

#include <random>

#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

namespace {

/// A scan of `scene` from base pose `body`, in base_link.
PointArray scanInBase(const sim::Scene& scene, const Eigen::Isometry3d& body, std::mt19937_64& rng) {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  PointArray p = sim::scan(scene, sim::ScannerModel{}, body * mount, rng);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3f q = mount.cast<float>() * p.point(i);
    p.x[i] = q.x(), p.y[i] = q.y(), p.z[i] = q.z();
  }
  return p;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

}  // namespace

TEST(OnlineMatcher, ChainsIncrementsFromBigOdometryErrors) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 4);
  sim::RobotMotion robot(scene, sim::MotionSettings{}, 5);
  sim::OdometrySimulator odometry(sim::OdometryError::Big, 6);
  std::mt19937_64 rng(7);
  OnlineMatcher m{OnlineMatcherSettings{}};
  for (int k = 0; k < 4; ++k) {
    if (k > 0) robot.advance();
    const Eigen::Isometry3d truth = robot.pose();
    const OnlineStep s = m.process(scanInBase(scene, truth, rng), 10.0 + k, odometry.next(truth));
    EXPECT_EQ(s.reason, k == 0 ? GateReason::FirstScan : GateReason::Accepted) << s.message;
    EXPECT_TRUE(s.reference_updated);
    // map = odom = world at the first scan, so the chained pose is comparable to the truth.
    EXPECT_LT(translationError(s.pose, truth), 0.05 * k + 1e-9) << "scan " << k;
  }
}

TEST(OnlineMatcher, TimeBackwardsResetsAndEmptyOrBadScansKeepTheReference) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Hall, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 0.5, 1.0);
  body.linear() = rotationFromRpy(0, 0, deg2rad(17));
  const PointArray scan = scanInBase(scene, body, rng);
  OnlineMatcher m{OnlineMatcherSettings{}};
  EXPECT_EQ(m.process(scan, 5.0, std::nullopt).reason, GateReason::FirstScan);

  OnlineStep s = m.process(PointArray{}, 6.0, std::nullopt);
  EXPECT_EQ(s.reason, GateReason::BadInput);
  EXPECT_FALSE(s.reference_updated);
  EXPECT_TRUE(m.hasReference());

  PointArray absurd = scan;
  absurd.push_back(1e7f, 1e7f, 1e7f);  // the grid would exceed the memory cap
  s = m.process(absurd, 7.0, std::nullopt);
  EXPECT_FALSE(s.reference_updated);
  EXPECT_NE(s.message.find("not used as reference"), std::string::npos) << s.message;
  EXPECT_TRUE(m.hasReference());

  s = m.process(scan, 8.0, std::nullopt);  // identity guess (no odometry), same scene
  EXPECT_FALSE(s.odometry_guess);
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;

  s = m.process(scan, 1.0, std::nullopt);  // time went backwards
  EXPECT_TRUE(s.time_reset);
  EXPECT_EQ(s.reason, GateReason::FirstScan);
}

TEST(OnlineMatcher, ConsecutiveRejectionsRaiseTheAlarmAndPropagateOdometry) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Park, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 0.5, scene.groundHeight(2, 0.5) + 1.0);
  const PointArray scan = scanInBase(scene, body, rng);
  OnlineMatcherSettings settings;
  settings.gate.max_correction_m = 0.05;  // the 0.3 m odometry error cannot be corrected
  settings.max_consecutive_rejections = 2;
  OnlineMatcher m(settings);
  Eigen::Isometry3d odom = Eigen::Isometry3d::Identity();
  m.process(scan, 1.0, odom);
  odom.translation().x() = 0.3;  // the same scan again: the truth is identity
  OnlineStep s = m.process(scan, 2.0, odom);
  EXPECT_EQ(s.reason, GateReason::CorrectionTooLarge) << s.message;
  EXPECT_FALSE(s.rejection_alarm);
  EXPECT_LT(translationError(s.pose, odom), 1e-9);  // odometry propagated
  odom.translation().x() = 0.6;
  s = m.process(scan, 3.0, odom);
  EXPECT_EQ(s.reason, GateReason::CorrectionTooLarge) << s.message;
  EXPECT_TRUE(s.rejection_alarm);
  EXPECT_EQ(s.consecutive_rejections, 2);
}
