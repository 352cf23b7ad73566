// The simulator: the tilting scanner against the paper's numbers (section 3.1), the scenes,
// the robot motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/sequence_motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

TEST(TiltingScanner, DefaultModelMatchesThePaper) {
  const sim::ScannerModel m;
  EXPECT_EQ(m.phiCount(), 361);  // 180 deg in 0.5 deg steps
  EXPECT_EQ(m.psiCount(), 181);  // 60 deg in 1/3 deg steps
  EXPECT_EQ(m.phiCount() * m.psiCount(), 65341);
  EXPECT_DOUBLE_EQ(m.max_range, 81.0);
  EXPECT_DOUBLE_EQ(m.range_noise, 0.04);
}

TEST(TiltingScanner, OrganisedSweepHasOnePointPerBeamAndRespectsTheRange) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Park, 1);
  const sim::ScannerModel m;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, scene.groundHeight(0, 0) + 1.0);
  pose.linear() = sim::sensorToBodyRotation();
  std::mt19937_64 rng(1);
  sim::SweepOptions organised;
  organised.keep_invalid = true;
  const PointArray all = sim::scan(scene, m, pose, rng, organised);
  ASSERT_EQ(all.size(), 65341u);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (std::isnan(all.x[i])) continue;
    ++valid;
    const double r = all.point(i).cast<double>().norm();
    EXPECT_LE(r, m.max_range);
    EXPECT_GE(all.y[i], -1e-3);  // phi in [0, 180] deg: eq. (1) gives y = C(psi) S(phi) r >= 0
  }
  EXPECT_GT(valid, 10000u);   // the ground and the trees return
  EXPECT_LT(valid, 65341u);   // the sky does not
  rng.seed(1);
  EXPECT_EQ(sim::scan(scene, m, pose, rng).size(), valid);  // unorganised: dropped, not NaN
}

TEST(TiltingScanner, Eq1GeometryOnAWall) {
  // A wall 10 m in front of the body: the beam at phi = 90, psi = 0 returns 10 m along +x.
  sim::Scene scene;
  scene.planes.push_back({Eigen::Vector3d(1, 0, 0), 10.0});
  sim::ScannerModel m;
  m.range_noise = 0.0;
  m.phi_min_deg = m.phi_max_deg = 90.0;
  m.psi_min_deg = m.psi_max_deg = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = sim::sensorToBodyRotation();
  std::mt19937_64 rng(1);
  const PointArray p = sim::scan(scene, m, pose, rng);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p.y[0], 10.0, 1e-5);  // sensor +Y looks along body +x
  EXPECT_NEAR(p.x[0], 0.0, 1e-5);
}

TEST(Scene, SameSeedSameWorld) {
  ASSERT_EQ(sim::allSceneTypes().size(), 10u);
  for (const sim::SceneType t : sim::allSceneTypes()) {
    const std::string name = sim::toString(t);
    EXPECT_EQ(sim::sceneTypeFromString(name), t);
    const sim::Scene a = sim::Scene::generate(t, 9), b = sim::Scene::generate(t, 9);
    EXPECT_EQ(a.boxes.size(), b.boxes.size());
    EXPECT_EQ(a.spheres.size(), b.spheres.size());
    const Eigen::Vector3d o(3, 0.5, 1.2), d = Eigen::Vector3d(1, 0.2, -0.1).normalized();
    EXPECT_EQ(a.raycast(o, d, 81), b.raycast(o, d, 81)) << name;
  }
  EXPECT_THROW(sim::sceneTypeFromString("moon"), std::invalid_argument);
}

TEST(Scene, CrowdMovesBetweenSweepsAndTheRestStays) {
  const sim::Scene world = sim::Scene::generate(sim::SceneType::Crowd, 3);
  ASSERT_GT(world.movers.size(), 50u);
  const sim::Scene a = world.at(0.0), b = world.at(2.0);
  EXPECT_TRUE(a.movers.empty());
  const std::size_t statics = world.boxes.size() + world.cylinders.size();
  ASSERT_EQ(a.boxes.size() + a.cylinders.size(), statics + world.movers.size());
  // The static primitives come first and are equal; every mover moved by |v| * 2 s.
  for (std::size_t i = 0; i < world.boxes.size(); ++i) EXPECT_EQ(a.boxes[i].lo, b.boxes[i].lo);
  std::size_t box = world.boxes.size(), cyl = world.cylinders.size();
  for (const sim::Mover& m : world.movers) {
    if (m.car) {
      EXPECT_NEAR((b.boxes[box].lo - a.boxes[box].lo).norm(), 2.0 * m.v.norm(), 1e-9);
      EXPECT_GE(m.v.norm(), 3.0);
      ++box;
    } else {
      const double d = std::hypot(b.cylinders[cyl].cx - a.cylinders[cyl].cx, b.cylinders[cyl].cy - a.cylinders[cyl].cy);
      EXPECT_NEAR(d, 2.0 * m.v.norm(), 1e-9);
      ++cyl;
    }
  }
  // The paper's worlds have no movers.
  EXPECT_TRUE(sim::Scene::generate(sim::SceneType::Urban, 3).movers.empty());
}

TEST(TiltingScanner, ArtefactsDropBeamsMixEdgesAndNoReturnPatchesSwallowHits) {
  // A box 10 m ahead in front of a wall 20 m ahead: along each 2D scan the range jumps at the
  // box's edges.
  sim::Scene scene;
  scene.planes.push_back({Eigen::Vector3d(1, 0, 0), 20.0});
  scene.boxes.push_back({Eigen::Vector3d(10, -2, -3), Eigen::Vector3d(11, 2, 3)});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = sim::sensorToBodyRotation();
  sim::ScannerModel clean;
  clean.range_noise = 0.0;
  std::mt19937_64 rng(1);
  const PointArray ref = sim::scan(scene, clean, pose, rng);
  auto between = [](const PointArray& p) {  // points neither on the box's face nor the wall
    int n = 0;
    for (std::size_t i = 0; i < p.size(); ++i) n += p.y[i] > 10.05 && p.y[i] < 19.95;
    return n;
  };
  EXPECT_EQ(between(ref), 0);
  sim::ScannerModel art = clean;
  art.mixed_pixels = 1.0;
  art.dropout = 0.1;
  const PointArray mixed = sim::scan(scene, art, pose, rng);
  EXPECT_GT(between(mixed), 100);  // mixed pixels at the box's two edges, each 2D scan
  EXPECT_LT(mixed.size(), 0.93 * ref.size());  // 10 % of the beams dropped
  EXPECT_GT(mixed.size(), 0.87 * ref.size());
  // A no-return patch over the box's face: none of its points return.
  sim::Scene patched = scene;
  patched.no_return.push_back({Eigen::Vector3d(10, 0, 0), 1.5});
  const PointArray p = sim::scan(patched, clean, pose, rng);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_FALSE(std::abs(p.y[i] - 10.0) < 0.01 && std::hypot(p.x[i], p.z[i]) < 1.4);
  }
  EXPECT_LT(p.size(), ref.size());
  // Defaults: no artefacts, so scans stay what they were.
  EXPECT_EQ(sim::ScannerModel{}.dropout, 0.0);
  EXPECT_EQ(sim::ScannerModel{}.mixed_pixels, 0.0);
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

TEST(TiltingScanner, ALineIsTheSweepsLineAndLiesInTheTiltedPlane) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  const sim::ScannerModel model;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = sim::sensorToBodyRotation();
  pose.translation() = Eigen::Vector3d(20, 0, 1);
  std::mt19937_64 a(5), b(5);
  const PointArray sweep = sim::scan(scene, model, pose, a, sim::SweepOptions{true});
  const double psi = deg2rad(model.psi_min_deg);
  const PointArray line = sim::scanLine(scene, model, pose, psi, b);
  ASSERT_EQ(line.size(), std::size_t(model.phiCount()));
  const Eigen::Matrix3d to_laser = Eigen::AngleAxisd(-psi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  int hits = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (std::isnan(line.x[i])) {
      EXPECT_TRUE(std::isnan(sweep.x[i]));
      continue;
    }
    ++hits;
    EXPECT_EQ(line.point(i), sweep.point(i));  // the sweep's first line, bit for bit
    const Eigen::Vector3d q = to_laser * line.point(i).cast<double>();  // in the laser's plane
    EXPECT_NEAR(q.z(), 0.0, 1e-4 * q.norm());
    EXPECT_NEAR(std::atan2(q.y(), q.x()), deg2rad(model.phi_min_deg + i * model.phi_step_deg), 1e-5);
  }
  EXPECT_GT(hits, 100);
}

TEST(SimMotion, DrivenPathZigzagsAboutItsAxisOnTheGround) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 1);
  const sim::DrivenPath path(scene, {1.0, 20.0, 2.0, 1.0}, 10.0, 0.0, 0.0);
  double max_y = 0.0;
  for (double t = 0.0; t <= 20.0; t += 0.1) {
    const Eigen::Isometry3d p = path.at(t);
    max_y = std::max(max_y, std::abs(p.translation().y()));
    EXPECT_NEAR(p.translation().z(), scene.groundHeight(p.translation().x(), p.translation().y()) + 1.0, 1e-9);
  }
  // Speed 1 m/s, yaw rate 20 deg/s flipping every 2 s: within v/w (1 - cos(20 deg)) of the axis.
  EXPECT_LE(max_y, 1.0 / deg2rad(20.0) * (1.0 - std::cos(deg2rad(20.0))) + 1e-9);
  // Travel at the speed: the arc length over 2 s is 2 m, its chord a little less.
  const double chord = (path.at(2.0).translation() - path.at(0.0).translation()).norm();
  EXPECT_NEAR(chord, 2.0 * std::sin(deg2rad(20.0)) / deg2rad(20.0), 1e-3);
}

TEST(SimMotion, SequenceRunKeepsTheRobotClearOfSolids) {
  // The sequence benchmark's 500 m runs: no sweep is taken where the robot's body would be
  // inside an object (a turn on the spot 0.25 m from one has the scanner face it from 0.1 m,
  // seeing nothing else), and the runs still turn on the spot.
  for (const sim::SceneType type : {sim::SceneType::Hall, sim::SceneType::Urban,
                                    sim::SceneType::Park, sim::SceneType::Natural}) {
    const sim::Scene scene = sim::Scene::generate(type, 1);
    const sim::SequenceSettings settings;
    sim::SequenceMotion robot(scene, settings, 2);
    int turns = 0;
    double last_yaw = 0.0;
    for (int k = 0; k < 433; ++k) {
      if (k > 0) robot.advance();
      const Eigen::Vector3d p = robot.pose().translation();
      const double ground = scene.groundHeight(p.x(), p.y());
      for (const double h : {0.2, 0.6, settings.height}) {
        EXPECT_FALSE(scene.insideSolid(Eigen::Vector3d(p.x(), p.y(), ground + h), settings.clearance))
            << "sweep " << k << " at " << p.transpose() << ", " << h << " m above the ground";
      }
      const double yaw = isometryToPose(robot.pose())[5];
      if (k > 0 && std::abs(wrapAngle(yaw - last_yaw)) > deg2rad(20.0)) ++turns;
      last_yaw = yaw;
    }
    EXPECT_GT(turns, 6) << "the run still turns on the spot";
  }
}
