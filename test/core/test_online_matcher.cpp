// OnlineMatcher (the nodelet's core), the acceptance gate and compass search, without ROS.
#include <gtest/gtest.h>

#include <random>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/compass_search.h"
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

TEST(CompassSearch, ClimbsASmoothPeakToTheStepResolution) {
  Vector6d peak;
  peak << 0.3, -0.2, 0.1, 0.02, -0.01, 0.03;
  auto f = [&](const Vector6d& x) { return -(x - peak).squaredNorm(); };
  CompassSettings s;
  s.levels = 10;
  const CompassResult r = compassMaximize(f, Vector6d::Zero(), s);
  EXPECT_LT((r.best - peak).norm(), 1e-3);
  EXPECT_GT(r.moves, 0);
  EXPECT_GE(r.best_value, r.initial_value);
}

TEST(CompassSearch, RespectsTheEvaluationBudgetAndValidates) {
  int calls = 0;
  CompassSettings s;
  s.max_evaluations = 17;
  compassMaximize([&](const Vector6d& x) { ++calls; return x.sum(); }, Vector6d::Zero(), s);
  EXPECT_EQ(calls, 17);
  s.levels = 0;
  EXPECT_THROW(compassMaximize([](const Vector6d&) { return 0.0; }, Vector6d::Zero(), s),
               std::invalid_argument);
}

TEST(AcceptanceGate, RejectsLowOverlapNoGainAndLargeCorrections) {
  RegistrationResult r;
  r.status = RegistrationStatus::Ok;
  r.reference_cubes = 1000;
  r.J = 500;
  r.J_guess = 400;
  r.pose << 0.2, 0, 0, 0, 0, 0;
  r.transform = poseToIsometry(r.pose);
  const Pose6 guess = Pose6::Zero();
  GateSettings g;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  g.min_overlap = 0.6;
  EXPECT_EQ(gate(r, guess, g), GateReason::LowOverlap);
  g = GateSettings{};
  g.min_j_gain = 200;
  EXPECT_EQ(gate(r, guess, g), GateReason::NoGain);
  g = GateSettings{};
  g.max_correction_m = 0.1;
  EXPECT_EQ(gate(r, guess, g), GateReason::CorrectionTooLarge);
  r.status = RegistrationStatus::NoOverlap;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::RegistrationFailed);
  g = GateSettings{};
  g.min_overlap = 1.5;
  EXPECT_THROW(validate(g), std::invalid_argument);
}

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

TEST(SimMotion, StaysInTheSceneAndMovesLikeThePapersPairs) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 1);
  sim::RobotMotion robot(scene, sim::MotionSettings{}, 2);
  Eigen::Isometry3d prev = robot.pose();
  for (int k = 0; k < 200; ++k) {
    robot.advance();
    const Eigen::Isometry3d inc = prev.inverse() * robot.pose();
    EXPECT_LE(inc.translation().head<2>().norm(), 5.0 + 1e-6);
    EXPECT_LE(rad2deg(std::abs(isometryToPose(inc)[5])), 45.0 + 2.0);
    EXPECT_LT(std::abs(robot.pose().translation().y()), 8.0);
    EXPECT_GT(robot.pose().translation().x(), -20.0);
    EXPECT_LT(robot.pose().translation().x(), 140.0);
    prev = robot.pose();
  }
  EXPECT_THROW(sim::odometryErrorFromString("huge"), std::invalid_argument);
}
