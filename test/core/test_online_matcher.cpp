// OnlineMatcher (the nodelet's core) without ROS: chaining, resets, rejections.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

namespace {

/// A scan of `scene` from base pose `body`, in base_link.
PointArray scanInBase(const sim::Scene& scene, const Eigen::Isometry3d& body, std::mt19937_64& rng) {
  return sim::scanInBody(scene, sim::ScannerModel{}, body, rng);
}

/// A scan of hall world 2 from (2, 0.5, 1) m, unturned, in base_link.
PointArray hallScan() {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Hall, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 0.5, 1.0);
  return scanInBase(scene, body, rng);
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

// OnlineStep::work counts what a step did: the first scan builds the reference and registers
// nothing; a scan with odometry registers once (no no-motion candidate); one without
// odometry also searches the no-motion candidate; the stage times add up to at most the total.
TEST(OnlineMatcher, WorkCountsAndTimesEachStage) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 4);
  sim::RobotMotion robot(scene, sim::MotionSettings{}, 5);
  std::mt19937_64 rng(7);
  OnlineMatcherSettings every_scan;
  every_scan.keyframes.distance = 0.0;  // every accepted scan becomes the keyframe
  every_scan.no_odometry_grid = PlanarGridSettings{};  // off: the prediction and the candidate
  OnlineMatcher m(every_scan);
  auto stagesWithinTotal = [](const OnlineWork& w) {
    return w.register_s + w.candidate_s + w.deskew_s + w.reference_s <= w.total_s;
  };
  Eigen::Isometry3d truth = robot.pose();
  OnlineStep s = m.process(scanInBase(scene, truth, rng), 1.0, truth);
  EXPECT_EQ(s.work.aligns, 0);
  EXPECT_TRUE(s.work.reference_built);
  EXPECT_GT(s.work.reference_s, 0.0);
  EXPECT_TRUE(stagesWithinTotal(s.work));

  robot.advance();
  truth = robot.pose();
  s = m.process(scanInBase(scene, truth, rng), 2.0, truth);
  ASSERT_EQ(s.reason, GateReason::Accepted) << s.message;
  EXPECT_EQ(s.work.aligns, 1);
  EXPECT_GE(s.work.searches, 1);
  EXPECT_EQ(s.work.searches, s.result.attempts);
  EXPECT_GT(s.work.evaluations, 0);
  EXPECT_GT(s.work.register_s, 0.0);
  EXPECT_EQ(s.work.candidate_s, 0.0);
  EXPECT_EQ(s.work.deskew_rounds, 0);
  EXPECT_TRUE(s.work.reference_built);
  EXPECT_TRUE(stagesWithinTotal(s.work));

  robot.advance();
  s = m.process(scanInBase(scene, robot.pose(), rng), 3.0, std::nullopt);  // no odometry
  EXPECT_EQ(s.work.aligns, 2) << "the prediction and the no-motion candidate";
  EXPECT_GT(s.work.candidate_s, 0.0);
  EXPECT_EQ(s.result.evaluations_grid, 0);
  EXPECT_TRUE(stagesWithinTotal(s.work));

  // With the planar grid (the default) one search covers both, seeded by the grid.
  every_scan.no_odometry_grid = OnlineMatcherSettings{}.no_odometry_grid;
  m.setSettings(every_scan);
  robot.advance();
  s = m.process(scanInBase(scene, robot.pose(), rng), 4.0, std::nullopt);
  EXPECT_EQ(s.work.aligns, 1);
  EXPECT_EQ(s.work.candidate_s, 0.0);
  // At least the grid's poses (more when the scan before was rejected: the yaw widens).
  EXPECT_GE(s.result.evaluations_grid, every_scan.no_odometry_grid.poses());
  EXPECT_GT(s.work.evaluations, s.result.evaluations_grid);
  EXPECT_TRUE(stagesWithinTotal(s.work));
}

// Without odometry, a look-around on the spot (30 deg per scan, out to 90 deg and back) after
// driving and stopping, as in the sequence benchmark's standing-still runs: every scan is
// accepted and right with the planar grid (the default), in the hall, the natural world and
// the park. Without it the searches from the constant-velocity prediction and from "no motion"
// within +-32 deg miss the turns. In the park the coarse stage's best maximum at the first
// turn is "no motion": only the retries from the first search's other coarse results
// (SearchSettings::retries, with the grid) reach the truth there.
class LookAround : public ::testing::TestWithParam<sim::SceneType> {};

TEST_P(LookAround, WithoutOdometryIsRegistered) {
  const sim::Scene scene = sim::Scene::generate(GetParam(), 1);
  auto run = [&](const OnlineMatcherSettings& settings, bool expect_all_right) {
    OnlineMatcher m(settings);
    std::mt19937_64 rng(11);
    int right = 0, scans = 0;
    const std::vector<std::pair<double, double>> path = {
        {10.0, 0.0},  {11.5, 0.0},  {13.0, 0.0},  {13.0, 0.0}, {13.0, 0.0}, {13.0, 30.0},
        {13.0, 60.0}, {13.0, 90.0}, {13.0, 60.0}, {13.0, 30.0}, {13.0, 0.0}, {14.5, 0.0}};
    for (const auto& [x, yaw_deg] : path) {
      Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
      body.translation() = Eigen::Vector3d(x, 0.0, scene.groundHeight(x, 0.0) + 1.0);
      body.linear() = rotationFromRpy(0.0, 0.0, deg2rad(yaw_deg));
      const OnlineStep s = m.process(scanInBase(scene, body, rng), 1.5 * scans, std::nullopt);
      if (scans++ == 0) continue;
      // map = the first scan's pose: the chained pose against the truth relative to it.
      Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
      first.translation() = Eigen::Vector3d(10.0, 0.0, scene.groundHeight(10.0, 0.0) + 1.0);
      const Eigen::Isometry3d err = (first.inverse() * body).inverse() * s.pose;
      const bool ok = s.accepted && err.translation().norm() < 0.05 &&
                      Eigen::AngleAxisd(err.linear()).angle() < deg2rad(0.5);
      right += ok;
      if (expect_all_right) {
        EXPECT_TRUE(ok) << "x " << x << " m, yaw " << yaw_deg << " deg: " << s.message << ", "
                        << err.translation().norm() << " m, "
                        << rad2deg(Eigen::AngleAxisd(err.linear()).angle()) << " deg off";
      }
    }
    return right;
  };
  const int scans = 11;
  EXPECT_EQ(run(OnlineMatcherSettings{}, true), scans);
  OnlineMatcherSettings off;
  off.no_odometry_grid = PlanarGridSettings{};
  EXPECT_LT(run(off, false), scans) << "the look-around without the grid";
}

INSTANTIATE_TEST_SUITE_P(OnlineMatcher, LookAround,
                         ::testing::Values(sim::SceneType::Hall, sim::SceneType::Natural,
                                           sim::SceneType::Park),
                         [](const auto& info) { return sim::toString(info.param); });

TEST(OnlineMatcher, TimeBackwardsResetsAndEmptyOrBadScansKeepTheReference) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Hall, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 0.5, 1.0);
  body.linear() = rotationFromRpy(0, 0, deg2rad(17));
  const PointArray scan = scanInBase(scene, body, rng);
  OnlineMatcherSettings every_scan;
  every_scan.keyframes.distance = 0.0;  // every accepted scan would become the keyframe
  OnlineMatcher m(every_scan);
  EXPECT_EQ(m.process(scan, 5.0, std::nullopt).reason, GateReason::FirstScan);

  OnlineStep s = m.process(PointArray{}, 6.0, std::nullopt);
  EXPECT_EQ(s.reason, GateReason::BadInput);
  EXPECT_FALSE(s.reference_updated);
  EXPECT_TRUE(m.hasReference());

  PointArray absurd = scan;
  absurd.push_back(1e7f, 1e7f, 1e7f);  // the grid would exceed the memory cap
  s = m.process(absurd, 7.0, std::nullopt);
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;
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

// A gap in the odometry: scans without it are registered from identity; the first scan with
// odometry again is guessed from the last one that had it, carried over the accepted
// increments in between. A scan without odometry whose registration is rejected (its pose is
// unknown) does not become the reference.
TEST(OnlineMatcher, OdometryGapIsBridgedFromTheLastScanWithOdometry) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 8);
  sim::MotionSettings motion;
  motion.step_min = 0.3, motion.step_max = 0.5, motion.yaw_change_max_deg = 3.0;
  sim::RobotMotion robot(scene, motion, 9);
  std::mt19937_64 rng(7);
  OnlineMatcherSettings every_scan;
  every_scan.keyframes.distance = 0.0;  // each scan the keyframe: the guess is scan to scan
  OnlineMatcher m(every_scan);
  // Odometry with a constant offset from the truth: map = odom o offset.
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() = Eigen::Vector3d(5.0, -3.0, 0.2);
  offset.linear() = rotationFromRpy(0.0, 0.0, deg2rad(30.0));
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 5; ++k) {
    if (k > 0) robot.advance();
    truth.push_back(robot.pose());
    const bool gap = k == 2;
    const std::optional<Eigen::Isometry3d> odom =
        gap ? std::nullopt : std::optional<Eigen::Isometry3d>(offset * robot.pose());
    const OnlineStep s = m.process(scanInBase(scene, robot.pose(), rng), 1.0 + k, odom);
    EXPECT_EQ(s.odometry_guess, k > 0 && !gap) << "scan " << k;
    EXPECT_EQ(s.reason, k == 0 ? GateReason::FirstScan : GateReason::Accepted) << s.message;
    if (k == 3) {
      // Guessed over scan 2 (no odometry): the guess is the true increment 2 -> 3.
      const Eigen::Isometry3d true_increment = truth[2].inverse() * truth[3];
      EXPECT_LT((poseToIsometry(s.guess).inverse() * true_increment).translation().norm(), 0.05);
    }
    // map = odom at the first scan: the pose is offset * truth throughout.
    EXPECT_LT(translationError(s.pose, offset * robot.pose()), 0.05) << "scan " << k;
  }

  // No odometry and a rejected registration (far outside the gate): not the reference.
  OnlineMatcherSettings tight = every_scan;
  tight.gate.max_correction_m = 1e-3;
  tight.max_consecutive_rejections = 3;
  m.setSettings(tight);
  robot.advance();
  OnlineStep s = m.process(scanInBase(scene, robot.pose(), rng), 10.0, std::nullopt);
  EXPECT_NE(s.reason, GateReason::Accepted);
  EXPECT_FALSE(s.reference_updated);
  EXPECT_NE(s.message.find("not used as reference"), std::string::npos) << s.message;
  // Once max_consecutive_rejections are reached, the chain moves on.
  s = m.process(scanInBase(scene, robot.pose(), rng), 11.0, std::nullopt);
  EXPECT_FALSE(s.reference_updated);
  s = m.process(scanInBase(scene, robot.pose(), rng), 12.0, std::nullopt);
  EXPECT_TRUE(s.rejection_alarm);
  EXPECT_TRUE(s.reference_updated);
}

// Dropped or rejected scans make the prediction span several increments, and the odometry
// error with them: the correction bounds grow with the time since the last known pose, in
// scan periods.
TEST(OnlineMatcher, CorrectionBoundsGrowWithTheScansTheGuessSpans) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Park, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 0.5, scene.groundHeight(2, 0.5) + 1.0);
  const PointArray scan = scanInBase(scene, body, rng);  // the same scan: the truth is identity
  OnlineMatcherSettings settings;
  settings.gate.max_correction_m = 0.05;
  OnlineMatcher m(settings);
  Eigen::Isometry3d odom = Eigen::Isometry3d::Identity();
  for (int k = 0; k < 4; ++k) {  // one scan per second
    const OnlineStep s = m.process(scan, double(k), odom);
    EXPECT_DOUBLE_EQ(s.gate_scale, 1.0);
  }
  odom.translation().x() = 0.1;  // 0.1 m odometry error over one period: beyond 0.05 m
  OnlineStep s = m.process(scan, 4.0, odom);
  EXPECT_EQ(s.reason, GateReason::CorrectionTooLarge) << s.message;
  EXPECT_DOUBLE_EQ(s.gate_scale, 1.0);
  odom.translation().x() = 0.1;  // the same 0.1 m, predicted from the last known scan (at 3 s)
  s = m.process(scan, 7.0, odom);  // over four periods: the rejected one and two dropped
  EXPECT_DOUBLE_EQ(s.gate_scale, 4.0);
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;
  EXPECT_NE(s.message.find("bounds x4"), std::string::npos) << s.message;
}

// Settings whose grids cannot be built for the current reference are refused at once, and the
// matcher goes on with the old ones (a live cube_edge far too small must not stop it).
TEST(OnlineMatcher, SettingsWhoseGridsCannotBeBuiltAreRefusedAndTheOldOnesStay) {
  const PointArray scan = hallScan();
  OnlineMatcherSettings settings;
  settings.registration.grid.max_cubes = std::uint64_t{1} << 24;
  OnlineMatcher m(settings);
  EXPECT_EQ(m.process(scan, 1.0, std::nullopt).reason, GateReason::FirstScan);
  OnlineMatcherSettings tiny = settings;
  tiny.registration.grid.cube_edge = 0.05;  // millions of cubes over the hall: beyond the cap
  EXPECT_THROW(m.setSettings(tiny), std::invalid_argument);
  EXPECT_EQ(m.settings().registration.grid.cube_edge, settings.registration.grid.cube_edge);
  const OnlineStep s = m.process(scan, 2.0, std::nullopt);
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;
  // A good change is built at once and used.
  OnlineMatcherSettings finer = settings;
  finer.registration.grid.cube_edge = 0.3;
  EXPECT_NO_THROW(m.setSettings(finer));
  EXPECT_EQ(m.process(scan, 3.0, std::nullopt).reason, GateReason::Accepted);
}

// Standing still: every scan is registered to the same keyframe, so the pose error does not
// grow with the scans (scan-to-scan chaining adds each scan's error to the next).
TEST(OnlineMatcher, StandingStillAddsNoDriftWithKeyframes) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(11);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(5, 0.3, scene.groundHeight(5, 0.3) + 1.0);
  OnlineMatcher m{OnlineMatcherSettings{}};
  const Eigen::Isometry3d odom = body;  // exact odometry: any error is the registration's
  Eigen::Isometry3d first_pose;
  for (int k = 0; k < 12; ++k) {
    const OnlineStep s = m.process(scanInBase(scene, body, rng), double(k), odom);  // new noise
    if (k == 0) first_pose = s.pose;
    EXPECT_EQ(s.reason, k == 0 ? GateReason::FirstScan : GateReason::Accepted) << s.message;
    EXPECT_EQ(s.reference_updated, k == 0) << "scan " << k;
    EXPECT_EQ(s.keyframes, 1);
    // One registration's error (the scene benchmark's scatter), not a sum over the scans.
    EXPECT_LT(translationError(s.pose, first_pose), 0.05) << "scan " << k;
  }
}

// Keyframes follow the motion thresholds; a submap merges the last K of them into the
// reference, and the chain stays on the truth.
TEST(OnlineMatcher, KeyframesFollowTheThresholdsAndTheSubmapMergesTheLastOnes) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Park, 5);
  sim::MotionSettings motion;
  motion.step_min = 0.6, motion.step_max = 0.8, motion.yaw_change_max_deg = 3.0;
  sim::RobotMotion robot(scene, motion, 6);
  sim::OdometrySimulator odometry(sim::OdometryError::Small, 7);
  std::mt19937_64 rng(8);
  OnlineMatcherSettings settings;
  settings.keyframes.distance = 1.0;  // every second scan or so
  settings.keyframes.angle = 1.0;
  settings.keyframes.submap_size = 3;
  OnlineMatcher m(settings);
  Eigen::Isometry3d keyframe_truth;
  int keyframes = 0;
  for (int k = 0; k < 8; ++k) {
    if (k > 0) robot.advance();
    const OnlineStep s = m.process(scanInBase(scene, robot.pose(), rng), double(k),
                                   odometry.next(robot.pose()));
    EXPECT_EQ(s.reason, k == 0 ? GateReason::FirstScan : GateReason::Accepted) << s.message;
    if (k > 0) {
      // A new keyframe exactly when the scan moved >= 1 m from the last (by the estimate).
      const double moved = (keyframe_truth.inverse() * robot.pose()).translation().norm();
      if (std::abs(moved - 1.0) > 0.1) {
        EXPECT_EQ(s.reference_updated, moved >= 1.0) << "scan " << k;
      }
    }
    if (s.reference_updated) keyframe_truth = robot.pose(), ++keyframes;
    EXPECT_EQ(s.keyframes, std::min(keyframes, 3));
    EXPECT_LT(translationError(s.pose, robot.pose()), 0.05) << "scan " << k;
  }
  EXPECT_GE(keyframes, 4);
  EXPECT_LE(keyframes, 6);
  OnlineMatcherSettings bad = settings;
  bad.keyframes.submap_size = 0;
  EXPECT_THROW(m.setSettings(bad), std::invalid_argument);
  bad.keyframes.submap_size = 1;  // shrinking the submap rebuilds the reference from the last
  m.setSettings(bad);
  robot.advance();
  const OnlineStep s = m.process(scanInBase(scene, robot.pose(), rng), 8.0, odometry.next(robot.pose()));
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;
  EXPECT_EQ(s.keyframes, 1);
}

namespace {

/// RMS distance [m] between two arrays of corresponding points.
double rmsDistance(const PointArray& a, const PointArray& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a.point(i) - b.point(i)).cast<double>().squaredNorm();
  return a.empty() ? 0.0 : std::sqrt(sum / double(a.size()));
}

/// Urban world 1 driven at 1 m/s and 20 deg/s (the yaw rate's sign flipping every sweep) with
/// 2 s sweeps taken back to back by the tilting scanner.
struct UrbanDrive {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 1);
  const double d = 2.0;  ///< [s] sweep duration
  const sim::DrivenPath path{scene, {1.0, 20.0, d, 1.0}, 30.0, 0.0, 0.0};
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  UrbanDrive() { mount.linear() = sim::sensorToBodyRotation(); }
  /// Sweep k, taken over (k - 1) d .. k d [s], lines cast from the true poses.
  sim::TimedSweep sweep(int k, std::mt19937_64& rng) const {
    return sim::scanDuringMotion(
        scene, sim::ScannerModel{}, [&](double t) { return path.at(t) * mount; }, k * d, d,
        k % 2 == 1, rng);
  }
};

/// The error of each registered increment of a run driven at 1 m/s and 20 deg/s with 2 s
/// sweeps, started standing still, odometry with the paper's "big" errors, every sweep placed
/// by that odometry at its lines' times (as an assembler and tf give it). `shape_errors`: per
/// sweep, the RMS distance [m] of the points as the step gives them (the de-skewed ones when
/// de-skewed, else as placed) to the sweep placed with the true motion.
std::vector<double> movingSweepErrors(bool deskew, std::vector<double>& angle_errors_deg,
                                      std::vector<double>& shape_errors) {
  const UrbanDrive drive;
  const sim::Scene& scene = drive.scene;
  const double d = drive.d;
  const sim::DrivenPath& path = drive.path;
  const Eigen::Isometry3d& mount = drive.mount;
  std::mt19937_64 rng(11);
  OnlineMatcherSettings s;
  s.deskew.enabled = deskew;
  OnlineMatcher m(s);
  Eigen::Isometry3d truth = path.at(0.0), odom = truth;
  Eigen::Isometry3d pose = m.process(sim::scanInBody(scene, sim::ScannerModel{}, truth, rng), 0.0, odom).pose;
  std::vector<double> errors;
  for (int k = 1; k <= 3; ++k) {
    const Eigen::Isometry3d next = path.at(k * d);
    const Eigen::Isometry3d increment = truth.inverse() * next;
    const Eigen::Isometry3d odom_increment = increment * sim::randomTransform(rng, 1.0, 8.0);
    const sim::TimedSweep sweep = drive.sweep(k, rng);
    const PointArray placed = sim::placeSweep(sweep, mount, odom_increment, d);
    odom = odom * odom_increment;
    const PointTimes times{sweep.time, true};
    const OnlineStep step = m.process(placed, k * d, odom, &times);
    EXPECT_TRUE(step.accepted) << step.message;
    EXPECT_EQ(step.deskewed, deskew);
    const PointArray truly_placed = sim::placeSweep(sweep, mount, increment, d);
    if (step.deskewed) {
      EXPECT_EQ(step.deskewed_points.size(), placed.size());
      shape_errors.push_back(rmsDistance(step.deskewed_points, truly_placed));
    } else {
      EXPECT_TRUE(step.deskewed_points.empty());
      shape_errors.push_back(rmsDistance(placed, truly_placed));
    }
    const Eigen::Isometry3d estimate = pose.inverse() * step.pose;
    errors.push_back(translationError(estimate, increment));
    angle_errors_deg.push_back(rad2deg(Eigen::AngleAxisd(estimate.linear() * increment.linear().transpose()).angle()));
    pose = step.pose;
    truth = next;
  }
  return errors;
}

}  // namespace

TEST(OnlineMatcher, DeskewWithTheRegisteredMotionUnbendsSweepsTakenWhileDriving) {
  std::vector<double> rigid_deg, deskew_deg, rigid_shape, deskew_shape;
  const std::vector<double> rigid = movingSweepErrors(false, rigid_deg, rigid_shape);
  const std::vector<double> deskewed = movingSweepErrors(true, deskew_deg, deskew_shape);
  // Registered rigidly, a sweep bent by the odometry's error lands decimetres off.
  EXPECT_GT(*std::max_element(rigid.begin(), rigid.end()), 0.1);
  // De-skewed with the registered motion: the stop-and-go accuracy (2 cm, 0.1 deg).
  for (std::size_t k = 0; k < deskewed.size(); ++k) {
    EXPECT_LT(deskewed[k], 0.02) << "increment " << k + 1;
    EXPECT_LT(deskew_deg[k], 0.1) << "increment " << k + 1;
  }
  // The points the step hands out (the nodelet's ~registered_cloud): bent by the odometry's
  // error as placed (measured 0.70-1.83 m RMS), re-placed to within millimetres of the true
  // shape when de-skewed (measured 3 mm).
  for (std::size_t k = 0; k < deskew_shape.size(); ++k) {
    std::printf("[deskew] sweep %zu: RMS to the true shape %.3f m placed, %.3f m de-skewed\n",
                k + 1, rigid_shape[k], deskew_shape[k]);
    EXPECT_GT(rigid_shape[k], 0.35) << "sweep " << k + 1;
    EXPECT_LT(deskew_shape[k], 0.006) << "sweep " << k + 1;
  }
}

TEST(OnlineMatcher, PointTimesOfTheWrongSizeAreRefusedAndEqualTimesAreRigid) {
  OnlineMatcher m{OnlineMatcherSettings{}};
  PointArray pts;
  pts.push_back(1, 2, 3);
  const PointTimes times{{0.0f, -0.1f}, true};
  EXPECT_THROW(m.process(pts, 0.0, std::nullopt, &times), std::invalid_argument);
  // A scan whose points share one time (stop and go) is registered as given: not de-skewed.
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a;
  a.translation() = Eigen::Vector3d(20, 0, 1);
  b.translation() = Eigen::Vector3d(21.5, 0, 1);
  m.process(scanInBase(scene, a, rng), 1.0, a);
  const PointArray scan = scanInBase(scene, b, rng);
  const PointTimes same{std::vector<float>(scan.size(), 0.0f), true};
  const OnlineStep step = m.process(scan, 2.0, b, &same);
  EXPECT_TRUE(step.accepted) << step.message;
  EXPECT_FALSE(step.deskewed);
}

namespace {

/// A 10 m block of random points around x = `x` [m] in the base frame.
PointArray blockAt(double x, std::mt19937_64& rng) {
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  PointArray p;
  for (int i = 0; i < 2000; ++i) p.push_back(float(x) + u(rng), u(rng), u(rng));
  return p;
}

bool finite(const OnlineStep& s) {
  return s.pose.matrix().allFinite() && s.increment.matrix().allFinite() &&
         s.motion.matrix().allFinite() && s.guess.allFinite() && s.correction.allFinite();
}

}  // namespace

// Without odometry, scans that never register (no overlap) are forced on after
// max_consecutive_rejections, each the next one's keyframe. The chain starts at a turned pose:
// its rounding must not grow from forced scan to forced scan until the pose is NaN.
TEST(OnlineMatcher, ForcedScansWithoutOdometryKeepTheChainFiniteAndRigid) {
  std::mt19937_64 rng(11);
  OnlineMatcher m{OnlineMatcherSettings{}};
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() = rotationFromRpy(deg2rad(3.0), deg2rad(-4.0), deg2rad(37.0));
  start.translation() = Eigen::Vector3d(12.0, -7.0, 1.5);
  m.restartAt(start);
  constexpr int kScans = 80;
  for (int k = 0; k < kScans; ++k) {
    // Each scan's points lie 100 m beyond the last one's: nothing overlaps.
    const OnlineStep s = m.process(blockAt(100.0 * k, rng), 1.0 * k, std::nullopt);
    ASSERT_TRUE(finite(s)) << "scan " << k << ": " << s.message;
    ASSERT_TRUE(isRigid(s.pose, 1e-9)) << "scan " << k << ": rotation drifted from orthonormal";
    if (k == 0) continue;
    EXPECT_FALSE(s.accepted) << "scan " << k;
    EXPECT_EQ(s.rejection_alarm, k >= OnlineMatcherSettings{}.max_consecutive_rejections) << "scan " << k;
    // No motion was ever registered: a forced scan stays where the chain started.
    EXPECT_LT((s.pose.translation() - start.translation()).norm(), 1e-6) << "scan " << k;
  }
}

// A step whose pose would not be finite never enters the chain: odometry with a NaN is ignored
// (the scan is registered as without odometry), and a start pose with one is refused.
TEST(OnlineMatcher, NonFiniteOdometryIsIgnoredAndANonFiniteStartIsRefused) {
  const PointArray scan = hallScan();
  OnlineMatcher m{OnlineMatcherSettings{}};
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(m.restartAt(bad), std::invalid_argument);
  EXPECT_THROW(m.process(scan, std::numeric_limits<double>::infinity(), std::nullopt),
               std::invalid_argument);

  OnlineStep s = m.process(scan, 1.0, bad);
  EXPECT_EQ(s.reason, GateReason::FirstScan);
  EXPECT_TRUE(s.pose.isApprox(Eigen::Isometry3d::Identity())) << "the NaN odometry was used";
  EXPECT_NE(s.message.find("odometry pose not finite"), std::string::npos) << s.message;
  Eigen::Isometry3d sheared = Eigen::Isometry3d::Identity();
  sheared.linear()(0, 1) = 0.5;  // not a rotation
  s = m.process(scan, 2.0, sheared);
  EXPECT_FALSE(s.odometry_guess);
  EXPECT_EQ(s.reason, GateReason::Accepted) << s.message;
  EXPECT_TRUE(finite(s));
}

TEST(OnlineMatcher, NoMotionDensePointsOutOfRangeIsRefusedByName) {
  for (const int n : {-1, 1001}) {
    OnlineMatcherSettings s;
    s.no_motion_dense_points = n;
    try {
      OnlineMatcher matcher(s);
      ADD_FAILURE() << n << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("no_motion_dense_points"), std::string::npos) << e.what();
    }
  }
  OnlineMatcherSettings off;
  off.no_motion_dense_points = 0;  // off is a valid setting
  EXPECT_NO_THROW(OnlineMatcher{off});
}

// The no-odometry grid is validated as wide as rejections can make its yaw (180 deg): a grid
// that would then exceed the pose limit is refused when the settings are given, not mid-run.
TEST(OnlineMatcher, NoOdometryGridAndDensePointsAreValidatedByName) {
  auto refusedNaming = [](const OnlineMatcherSettings& s, const std::string& name) {
    try {
      OnlineMatcher matcher(s);
      ADD_FAILURE() << "accepted: " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  OnlineMatcherSettings s;
  s.no_odometry_grid.half_width_m = 12.0;  // 97 x 97 x 31 poses now, x 121 yaw steps at 180 deg
  refusedNaming(s, "planar grid");
  s = OnlineMatcherSettings{};
  s.no_odometry_dense_points = -1;
  refusedNaming(s, "no_odometry_dense_points");
  s = OnlineMatcherSettings{};
  s.no_odometry_grid = PlanarGridSettings{};  // off is a valid setting
  EXPECT_NO_THROW(OnlineMatcher{s});
}

namespace {

/// The step of a sweep taken after a rejected scan: a run driven at 1 m/s and 20 deg/s with
/// 2 s sweeps in urban world 1, started standing still; sweep 1 with the true odometry; scan 2
/// lost (empty: a rejection); sweep 3 with the true odometry at its end but with the odometry
/// at scan 2 off by `lost_odometry_error` (a yaw [deg] about the vertical), so that the motion
/// inside sweep 3 (odometry at 2 to odometry at 3) is bent by as much and nothing registered
/// corrects it. `increment_error`: sweep 3's pose error against sweep 1 [m], [deg].
OnlineStep sweepAfterARejection(bool check, double lost_odometry_error_deg,
                                std::pair<double, double>& increment_error) {
  const UrbanDrive drive;
  const double d = drive.d;
  const sim::DrivenPath& path = drive.path;
  std::mt19937_64 rng(5);
  OnlineMatcherSettings s;
  if (!check) s.deskew.max_rms_ratio = s.deskew.min_plane_fraction_ratio = 0.0;
  OnlineMatcher m(s);
  m.process(sim::scanInBody(drive.scene, sim::ScannerModel{}, path.at(0.0), rng), 0.0, path.at(0.0));
  const auto sweepAt = [&](int k, const Eigen::Isometry3d& placed_increment) {
    const sim::TimedSweep sweep = drive.sweep(k, rng);
    return std::make_pair(sim::placeSweep(sweep, drive.mount, placed_increment, d), sweep.time);
  };
  const auto [first, first_tau] = sweepAt(1, path.at(0.0).inverse() * path.at(d));
  const PointTimes first_times{first_tau, true};
  const OnlineStep one = m.process(first, d, path.at(d), &first_times);
  EXPECT_TRUE(one.accepted) << one.message;
  Eigen::Isometry3d lost_odom = path.at(2 * d);
  lost_odom.linear() = lost_odom.linear() *
      Eigen::AngleAxisd(deg2rad(lost_odometry_error_deg), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const OnlineStep two = m.process(PointArray{}, 2 * d, lost_odom);
  EXPECT_EQ(two.reason, GateReason::BadInput);
  const auto [third, third_tau] = sweepAt(3, lost_odom.inverse() * path.at(3 * d));
  const PointTimes third_times{third_tau, true};
  const OnlineStep three = m.process(third, 3 * d, path.at(3 * d), &third_times);
  const Eigen::Isometry3d estimate = one.pose.inverse() * three.pose;
  const Eigen::Isometry3d truth = path.at(d).inverse() * path.at(3 * d);
  increment_error = {translationError(estimate, truth),
                     rad2deg(Eigen::AngleAxisd(estimate.linear() * truth.linear().transpose()).angle())};
  std::printf("[bent sweep] check %s, odometry at the lost scan off %.0f deg: %s; plane RMS "
              "%.2f cm (sweep 1 %.2f cm); fraction on planes %.3f (sweep 1 %.3f); %.3f m, %.2f deg off\n", check ? "on" : "off", lost_odometry_error_deg,
              toString(three.reason).c_str(), 100.0 * three.result.plane_rms, 100.0 * one.result.plane_rms,
              double(three.result.plane_correspondences) / three.result.points_used,
              double(one.result.plane_correspondences) / one.result.points_used,
              increment_error.first, increment_error.second);
  return three;
}

}  // namespace

TEST(OnlineMatcher, ASweepStillBentAfterARejectionIsRejected) {
  std::pair<double, double> error;
  // The odometry right at the lost scan: the sweep's motion is right, the sweep accepted.
  const OnlineStep straight = sweepAfterARejection(true, 0.0, error);
  EXPECT_TRUE(straight.accepted) << straight.message;
  EXPECT_LT(error.first, 0.02);
  EXPECT_LT(error.second, 0.1);
  // Off by 8 deg there (the "big" odometry's bound): the sweep stays bent by as much, its
  // residual on the reference's planes shows it, and it is rejected, not made a keyframe.
  const OnlineStep bent = sweepAfterARejection(true, 8.0, error);
  EXPECT_EQ(bent.reason, GateReason::BentSweep) << bent.message;
  EXPECT_FALSE(bent.accepted);
  EXPECT_FALSE(bent.reference_updated);
  EXPECT_TRUE(bent.deskewed_points.empty());
  // Without the check the same sweep is accepted wrong.
  const OnlineStep unchecked = sweepAfterARejection(false, 8.0, error);
  EXPECT_TRUE(unchecked.accepted) << unchecked.message;
  EXPECT_TRUE(error.first > 0.10 || error.second > 1.0);
}
