// The simulator: the tilting scanner against the paper's numbers (section 3.1), the scenes,
// the robot motion.
#include <gtest/gtest.h>

#include <cmath>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/sim/motion.h"
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
  for (const char* name : {"hall", "urban", "park", "natural"}) {
    const auto t = sim::sceneTypeFromString(name);
    const sim::Scene a = sim::Scene::generate(t, 9), b = sim::Scene::generate(t, 9);
    EXPECT_EQ(a.boxes.size(), b.boxes.size());
    EXPECT_EQ(a.spheres.size(), b.spheres.size());
    const Eigen::Vector3d o(3, 0.5, 1.2), d = Eigen::Vector3d(1, 0.2, -0.1).normalized();
    EXPECT_EQ(a.raycast(o, d, 81), b.raycast(o, d, 81)) << name;
  }
  EXPECT_THROW(sim::sceneTypeFromString("moon"), std::invalid_argument);
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
