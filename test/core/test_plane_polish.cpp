// The point-to-plane polish (plane_map.h, plane_polish.h) and the covariance helpers
// (pose_covariance.h): planes of known surfaces, convergence from a few centimetres off to a
// known transform, the covariance's shape, and the weak direction of a corridor.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "cube_scan_matcher/core/plane_map.h"
#include "cube_scan_matcher/core/plane_polish.h"
#include "cube_scan_matcher/core/pose_covariance.h"

using namespace cube_scan_matcher;

namespace {

/// Points on the rectangle {origin + a u + b v : a in [0, la], b in [0, lb]} every `step` m,
/// with uniform noise of +-noise m along u x v.
void addRectangle(PointArray& out, const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                  const Eigen::Vector3d& v, double la, double lb, double step, double noise,
                  std::mt19937_64& rng) {
  std::uniform_real_distribution<double> n(-noise, noise);
  const Eigen::Vector3d normal = u.cross(v).normalized();
  for (double a = 0.0; a <= la; a += step) {
    for (double b = 0.0; b <= lb; b += step) {
      const Eigen::Vector3d p = origin + a * u + b * v + n(rng) * normal;
      out.push_back(float(p.x()), float(p.y()), float(p.z()));
    }
  }
}

/// A room-like scene with planes in every direction: floor, two walls, a back wall and two
/// slanted boxes' faces. `corridor` keeps only the floor, a ceiling and the two side walls
/// along x (nothing fixes x).
PointArray makeScene(bool corridor, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  PointArray p;
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  addRectangle(p, {-10, -4, 0}, X, Y, 20, 8, 0.1, 0.01, rng);   // floor
  addRectangle(p, {-10, -4, 0}, X, Z, 20, 3, 0.1, 0.01, rng);   // right wall
  addRectangle(p, {-10, 4, 0}, X, Z, 20, 3, 0.1, 0.01, rng);    // left wall
  if (corridor) {
    addRectangle(p, {-10, -4, 3}, X, Y, 20, 8, 0.1, 0.01, rng);  // ceiling
    return p;
  }
  addRectangle(p, {10, -4, 0}, Y, Z, 8, 3, 0.1, 0.01, rng);     // back wall
  const Eigen::Vector3d d = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d e = Eigen::Vector3d(1, -1, 0).normalized();
  addRectangle(p, {2, -2, 0}, d, Z, 2, 1.5, 0.1, 0.01, rng);    // slanted faces
  addRectangle(p, {-3, 1, 0}, e, Z, 2, 1.5, 0.1, 0.01, rng);
  return p;
}

PointArray transformed(const PointArray& in, const Eigen::Isometry3d& T) {
  PointArray out;
  appendTransformed(out, in, T);
  return out;
}

Eigen::Isometry3d truthTransform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotationFromRpy(0.01, -0.02, deg2rad(7.0));
  T.translation() = Eigen::Vector3d(0.8, -0.3, 0.05);
  return T;
}

}  // namespace

TEST(PlaneMap, FitsTheSurfaceAndRefusesLinesAndEmptySpace) {
  std::mt19937_64 rng(1);
  PointArray p;
  addRectangle(p, {0, 0, 1}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 3, 3, 0.05,
               0.005, rng);
  for (double x = 10.0; x < 13.0; x += 0.05) p.push_back(float(x), 0.5f, 0.5f);  // a line
  const PlaneMap map(p, 0.25, 6, 0.1);
  const LocalPlane* plane = map.planeAt({1.5, 1.5, 1.02});
  ASSERT_NE(plane, nullptr);
  EXPECT_NEAR(std::abs(plane->normal.z()), 1.0, 1e-3);
  EXPECT_NEAR(plane->mean.z(), 1.0, 5e-3);
  EXPECT_EQ(map.planeAt({11.5, 0.5, 0.5}), nullptr);  // a line is no plane
  EXPECT_EQ(map.planeAt({1.5, 1.5, 5.0}), nullptr);   // no reference point there
  EXPECT_EQ(PlaneMap().planeAt({0, 0, 0}), nullptr);
  EXPECT_THROW(PlaneMap(p, 0.0, 6, 0.1), std::invalid_argument);
}

TEST(PlanePolish, ConvergesToTheKnownTransformFromCentimetresOff) {
  const PointArray reference = makeScene(false, 2);
  const Eigen::Isometry3d truth = truthTransform();  // scan -> reference
  const PointArray scan = transformed(makeScene(false, 3), truth.inverse());
  const PlaneMap map(reference, 0.25, 6, 0.1);
  const PolishSettings s;
  Pose6 start = isometryToPose(truth);
  start.head<3>() += Eigen::Vector3d(0.04, -0.03, 0.02);
  start.tail<3>() += Eigen::Vector3d(0.004, -0.003, 0.005);  // 0.2-0.3 deg
  const PolishResult r = polishOnPlanes(map, scan, start, s);
  ASSERT_TRUE(r.applied) << r.reason;
  const Eigen::Isometry3d est = poseToIsometry(r.pose);
  EXPECT_LT((est.translation() - truth.translation()).norm(), 0.002);
  EXPECT_LT(rad2deg(Eigen::AngleAxisd(est.linear() * truth.linear().transpose()).angle()), 0.02);
  EXPECT_FALSE(r.degenerate) << r.weak_ratio;
  EXPECT_LT(r.rms, 0.02);
  // The covariance is symmetric positive definite, with standard deviations below a millimetre
  // for thousands of points with 1 cm noise (times the default covariance_scale).
  EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(std::sqrt(r.covariance(0, 0)), 1e-3);
  // covariance_scale multiplies it.
  PolishSettings scaled = s;
  scaled.covariance_scale = 4.0 * s.covariance_scale;
  const PolishResult r4 = polishOnPlanes(map, scan, start, scaled);
  EXPECT_NEAR(r4.covariance(0, 0), 4.0 * r.covariance(0, 0), 1e-15);
}

TEST(PlanePolish, ACorridorIsFlaggedAlongItsAxisAndNotMovedAlongIt) {
  const PointArray reference = makeScene(true, 2);
  const Eigen::Isometry3d truth = truthTransform();
  const PointArray scan = transformed(makeScene(true, 3), truth.inverse());
  const PlaneMap map(reference, 0.25, 6, 0.1);
  Pose6 start = isometryToPose(truth);
  start[0] += 0.05;  // 5 cm along the corridor: nothing can tell
  start[1] += 0.03;  // 3 cm across it: the walls fix it
  const PolishResult r = polishOnPlanes(map, scan, start, PolishSettings{});
  ASSERT_TRUE(r.applied) << r.reason;
  EXPECT_TRUE(r.degenerate) << r.weak_ratio;
  EXPECT_GT(std::abs(r.weak_direction[0]), 0.9);  // along x
  EXPECT_NEAR(r.pose[1], isometryToPose(truth)[1], 0.003);
  EXPECT_NEAR(r.pose[0], start[0], 0.01);  // left where the cube stages put it
  // Its predicted standard deviation along the axis dwarfs the one across it.
  EXPECT_GT(r.covariance(0, 0), 100.0 * r.covariance(1, 1));
}

TEST(PlanePolish, GivesUpWithoutPlanesAndKeepsThePose) {
  const PointArray reference = makeScene(false, 2);
  const PlaneMap map(reference, 0.25, 6, 0.1);
  PointArray far;
  for (int i = 0; i < 100; ++i) far.push_back(100.f + float(i), 100.f, 100.f);
  const Pose6 start = isometryToPose(truthTransform());
  const PolishResult r = polishOnPlanes(map, far, start, PolishSettings{});
  EXPECT_FALSE(r.applied);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.pose, start);
  EXPECT_FALSE(polishOnPlanes(PlaneMap(), far, start, PolishSettings{}).applied);
  Pose6 nan = start;
  nan[2] = std::nan("");
  EXPECT_FALSE(polishOnPlanes(map, makeScene(false, 3), nan, PolishSettings{}).applied);
}

TEST(PlanePolish, SettingsAreValidated) {
  PolishSettings s;
  EXPECT_NO_THROW(validate(s));
  s.kernel = 0.0;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s = PolishSettings{};
  s.covariance_scale = 0.5;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.enabled = false;  // not checked when off
  EXPECT_NO_THROW(validate(s));
}

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
