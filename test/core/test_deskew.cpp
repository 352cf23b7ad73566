// De-skew (core/deskew.h): the SE(3) exponential and logarithm, and re-placing a sweep
// placed with one constant-velocity motion by another, against points placed exactly.
#include <gtest/gtest.h>

#include <random>

#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

namespace {

Eigen::Isometry3d motion(double x, double y, double z, double roll, double pitch, double yaw) {
  Pose6 p;
  p << x, y, z, deg2rad(roll), deg2rad(pitch), deg2rad(yaw);
  return poseToIsometry(p);
}

double distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).norm();
}

}  // namespace

TEST(Deskew, LogAndExpAreInverse) {
  for (const Eigen::Isometry3d& T :
       {motion(0, 0, 0, 0, 0, 0), motion(2, -1, 0.3, 1, -2, 40), motion(0.001, 0, 0, 0, 0, 1e-7),
        motion(-3, 4, 1, 20, 30, -170), motion(1, 1, 1, 0, 0, 179.9)}) {
    EXPECT_LT(distance(expMotion(logMotion(T)), T), 1e-9);
  }
}

TEST(Deskew, ConstantTwistIsAnArcInThePlane) {
  // 2 m forward while turning 90 deg left: a quarter circle of radius 2 / (pi / 2).
  Twist xi;
  xi << 2.0, 0, 0, 0, 0, M_PI / 2;
  const Eigen::Isometry3d T = expMotion(xi);
  const double r = 2.0 / (M_PI / 2);
  EXPECT_NEAR(T.translation().x(), r, 1e-12);
  EXPECT_NEAR(T.translation().y(), r, 1e-12);
  // Half the time: half the angle on the same circle.
  const Eigen::Isometry3d H = motionAt(xi, -0.5, 1.0);  // back in time: the start side
  EXPECT_NEAR(Eigen::AngleAxisd(H.linear()).angle(), M_PI / 4, 1e-12);
  EXPECT_NEAR(H.translation().norm(), 2 * r * std::sin(M_PI / 8), 1e-12);
}

TEST(Deskew, ReplacesPointsPlacedWithAWrongMotionByTheTrueOne) {
  const Eigen::Isometry3d truth = motion(1.8, 0.3, 0.05, 1, -1, 25);
  const Eigen::Isometry3d placed = motion(1.0, -0.6, 0.5, 8, -6, 12);  // "big" odometry error
  const double interval = 2.0;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-20.0, 20.0), ut(-interval, 0.0);
  PointArray raw, as_placed, exact;
  std::vector<float> tau;
  for (int i = 0; i < 1000; ++i) {
    // One line per 10 points: the same time, as a 2D line of a tilting scanner.
    if (i % 10 == 0) tau.push_back(float(ut(rng)));
    else tau.push_back(tau.back());
    const Eigen::Vector3d p(u(rng), u(rng), 0.1 * u(rng));  // in the sensor at its own time
    raw.push_back(float(p.x()), float(p.y()), float(p.z()));
    const Eigen::Vector3d q = motionAt(logMotion(placed), tau.back(), interval) * p;
    const Eigen::Vector3d t = motionAt(logMotion(truth), tau.back(), interval) * p;
    as_placed.push_back(float(q.x()), float(q.y()), float(q.z()));
    exact.push_back(float(t.x()), float(t.y()), float(t.z()));
  }
  PointArray fixed = as_placed;
  deskew(fixed, tau, velocityOf(placed, interval), velocityOf(truth, interval));
  double worst = 0.0, before = 0.0;
  for (std::size_t i = 0; i < fixed.size(); ++i) {
    worst = std::max(worst, double((fixed.point(i) - exact.point(i)).norm()));
    before = std::max(before, double((as_placed.point(i) - exact.point(i)).norm()));
  }
  EXPECT_GT(before, 1.0);   // the placed sweep was bent by metres
  EXPECT_LT(worst, 1e-4);   // float rounding only
  // A rigid sweep (placed = identity) de-skewed with the truth is the exact one too.
  PointArray rigid = raw;
  deskew(rigid, tau, Twist::Zero(), velocityOf(truth, interval));
  for (std::size_t i = 0; i < rigid.size(); ++i) EXPECT_LT((rigid.point(i) - exact.point(i)).norm(), 1e-4);
}

TEST(Deskew, BadInputIsRefused) {
  PointArray pts;
  pts.push_back(1, 2, 3);
  EXPECT_THROW(deskew(pts, {}, Twist::Zero(), Twist::Zero()), std::invalid_argument);
  EXPECT_EQ(velocityOf(motion(1, 0, 0, 0, 0, 0), 0.0), Twist::Zero());  // no interval: no velocity
}
