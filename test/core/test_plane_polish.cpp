// The point-to-plane polish (plane_map.h, plane_polish.h): planes of known surfaces,
// convergence from a few centimetres off to a known transform, the covariance's shape, and the
// weak direction of a corridor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>

#include "cube_scan_matcher/core/parallel.h"
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

// The test pair: the reference scene, the truth (scan -> reference), the scan seen from it and
// the reference's plane map (0.25 m voxels).
struct KnownPair {
  explicit KnownPair(bool corridor)
      : reference(makeScene(corridor, 2)),
        truth(truthTransform()),
        scan(transformed(makeScene(corridor, 3), truth.inverse())),
        map(reference, 0.25, 6, 0.1) {}
  PointArray reference;
  Eigen::Isometry3d truth;
  PointArray scan;
  PlaneMap map;
};

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
  const KnownPair known(false);
  const PolishSettings s;
  Pose6 start = isometryToPose(known.truth);
  start.head<3>() += Eigen::Vector3d(0.04, -0.03, 0.02);
  start.tail<3>() += Eigen::Vector3d(0.004, -0.003, 0.005);  // 0.2-0.3 deg
  const PolishResult r = polishOnPlanes(known.map, known.scan, start, s);
  ASSERT_TRUE(r.applied) << r.reason;
  const Eigen::Isometry3d est = poseToIsometry(r.pose);
  EXPECT_LT((est.translation() - known.truth.translation()).norm(), 0.002);
  EXPECT_LT(rad2deg(Eigen::AngleAxisd(est.linear() * known.truth.linear().transpose()).angle()), 0.02);
  EXPECT_FALSE(r.degenerate) << r.weak_ratio;
  EXPECT_LT(r.rms, 0.02);
  // It reports how far it moved the pose: the start's offset, 5.4 cm and 0.3-0.4 deg.
  EXPECT_NEAR(r.shift_m, (start.head<3>() - isometryToPose(known.truth).head<3>()).norm(), 0.003);
  EXPECT_GT(rad2deg(r.shift_rad), 0.2);
  EXPECT_LT(rad2deg(r.shift_rad), 0.5);
  // The covariance is symmetric positive definite, with standard deviations below a millimetre
  // for thousands of points with 1 cm noise (times the default covariance_scale).
  EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(std::sqrt(r.covariance(0, 0)), 1e-3);
  // covariance_scale multiplies the plain term (the clustered term off), and the clustered
  // term adds to it.
  PolishSettings plain = s;
  plain.covariance_cell_m = 0.0;
  const PolishResult r1 = polishOnPlanes(known.map, known.scan, start, plain);
  PolishSettings scaled = plain;
  scaled.covariance_scale = 4.0 * s.covariance_scale;
  const PolishResult r4 = polishOnPlanes(known.map, known.scan, start, scaled);
  EXPECT_NEAR(r4.covariance(0, 0), 4.0 * r1.covariance(0, 0), 1e-15);
  for (int k = 0; k < 6; ++k) EXPECT_GE(r.covariance(k, k), r1.covariance(k, k));
}

// The clustered covariance: two scans of the same room with the same spread of residuals, one
// with independent noise on every point, one whose 1 m tiles are each shifted along their
// normal (an error all the points of a patch share, as a trunk's tangent plane). The plain
// term sees the same sigma^2 in both; the clustered term must tell them apart.
TEST(PlanePolish, ErrorsSharedByAPatchWidenTheClusteredCovariance) {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  struct Face {
    Eigen::Vector3d origin, u, v;
    double la, lb;
  };
  const Face faces[] = {{{-10, -4, 0}, X, Y, 20, 8}, {{-10, -4, 0}, X, Z, 20, 3},
                        {{-10, 4, 0}, X, Z, 20, 3},  {{10, -4, 0}, Y, Z, 8, 3},
                        {{2, -2, 0}, Eigen::Vector3d(1, 1, 0).normalized(), Z, 2, 1.5}};
  // tile_sd: each 1 m tile shifted by N(0, tile_sd) along its normal; noise: uniform per point.
  // The room is moved off the 1 m cubes' faces: a surface lying on a face would have its
  // points sorted into the cubes on either side by the sign of their residuals.
  const Eigen::Vector3d off_grid(0.37, 0.29, 0.43);
  auto room = [&](double tile_sd, double noise, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> shift(0.0, tile_sd);
    PointArray p;
    for (const Face& f : faces) {
      const Eigen::Vector3d n = f.u.cross(f.v).normalized();
      for (double a = 0.0; a < f.la; a += 1.0) {
        for (double b = 0.0; b < f.lb; b += 1.0) {
          const double off = tile_sd > 0.0 ? shift(rng) : 0.0;
          addRectangle(p, off_grid + f.origin + a * f.u + b * f.v + off * n, f.u, f.v,
                       std::min(0.95, f.la - a), std::min(0.95, f.lb - b), 0.1, noise, rng);
        }
      }
    }
    return p;
  };
  const PlaneMap map(room(0.0, 0.002, 2), 0.25, 6, 0.1);
  // Uniform noise of +-1.7 cm has the sd (1 cm) of the tiles' shifts.
  const PointArray independent = room(0.0, 0.0173, 3), shared = room(0.01, 0.0, 3);
  PolishSettings plain;
  plain.covariance_cell_m = 0.0;
  PolishSettings clustered;
  clustered.covariance_cell_m = 1.0;
  clustered.covariance_cell_scale = 1.0;
  clustered.covariance_scale = 1.0;
  auto sd = [&](const PointArray& scan, const PolishSettings& s, int axis) {
    const PolishResult r = polishOnPlanes(map, scan, Pose6::Zero(), s);
    EXPECT_TRUE(r.applied) << r.reason;
    return std::sqrt(r.covariance(axis, axis));
  };
  for (int axis : {0, 1, 2, 5}) {
    const double plain_ratio = sd(shared, plain, axis) / sd(independent, plain, axis);
    const double clustered_ratio = sd(shared, clustered, axis) / sd(independent, clustered, axis);
    EXPECT_LT(plain_ratio, 1.5) << "axis " << axis;
    EXPECT_GT(clustered_ratio, 2.5) << "axis " << axis;  // measured 3.2-3.7
  }
  // Off (covariance_cell_m 0) or scale 0 adds nothing; out-of-range settings are refused.
  PolishSettings zero = plain;
  zero.covariance_cell_m = 1.0;
  zero.covariance_cell_scale = 0.0;
  EXPECT_EQ(sd(shared, zero, 0), sd(shared, plain, 0));
  PolishSettings bad;
  bad.covariance_cell_m = -1.0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

// The jackknife (covariance_jackknife_cap): a corridor along x whose x only two small end
// tiles fix, each shifted along x by its own error. The fit splits the difference, so each
// tile's residual is half its error and the plain clustered term sees half the spread (a
// quarter of the variance); left out in turn, each tile's share is its whole error. Along y
// and z, which long walls and the floor fix across many cubes, the two agree.
TEST(PlanePolish, TheJackknifeWidensWhatFewCubesFix) {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d off_grid(0.37, 0.29, 0.43);  // surfaces off the 1 m cubes' faces
  auto corridor = [&](double shift_a, double shift_b, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    PointArray p;
    addRectangle(p, off_grid + Eigen::Vector3d(-10, -4, 0), X, Y, 20, 8, 0.1, 0.003, rng);
    addRectangle(p, off_grid + Eigen::Vector3d(-10, -4, 0), X, Z, 20, 3, 0.1, 0.003, rng);
    addRectangle(p, off_grid + Eigen::Vector3d(-10, 4, 0), X, Z, 20, 3, 0.1, 0.003, rng);
    // The two tiles (0.8 m, inside one 1 m cube each), facing along x.
    addRectangle(p, off_grid + Eigen::Vector3d(-6 + shift_a, -1.2, 0.6), Y, Z, 0.8, 0.8, 0.05, 0.003, rng);
    addRectangle(p, off_grid + Eigen::Vector3d(6 + shift_b, 0.75, 0.6), Y, Z, 0.8, 0.8, 0.05, 0.003, rng);
    return p;
  };
  const PlaneMap map(corridor(0.0, 0.0, 2), 0.25, 6, 0.1);
  const PointArray scan = corridor(0.02, -0.01, 3);
  PolishSettings plain;
  plain.covariance_cell_m = 1.0;
  plain.covariance_cell_scale = 1.0;
  plain.covariance_scale = 1.0;
  plain.covariance_jackknife_cap = 0.0;
  PolishSettings jackknife = plain;
  jackknife.covariance_jackknife_cap = 100.0;
  const PolishResult a = polishOnPlanes(map, scan, Pose6::Zero(), plain);
  const PolishResult b = polishOnPlanes(map, scan, Pose6::Zero(), jackknife);
  ASSERT_TRUE(a.applied) << a.reason;
  ASSERT_TRUE(b.applied) << b.reason;
  EXPECT_EQ(a.pose, b.pose);  // the covariance only
  EXPECT_NEAR(a.pose[0], -0.005, 0.002);  // back by the tiles' mean shift
  const double ratio_x = std::sqrt(b.covariance(0, 0) / a.covariance(0, 0));
  EXPECT_GT(ratio_x, 1.7);  // 2 for the clustered term alone
  EXPECT_LT(ratio_x, 2.2);
  for (int axis : {1, 2}) {
    EXPECT_LT(std::sqrt(b.covariance(axis, axis) / a.covariance(axis, axis)), 1.15) << "axis " << axis;
  }
  // A cap of 1 or less is off; a cap widens a cube's share at most that many times in sd.
  PolishSettings off = jackknife;
  off.covariance_jackknife_cap = 1.0;
  EXPECT_EQ(polishOnPlanes(map, scan, Pose6::Zero(), off).covariance, a.covariance);
  PolishSettings capped = jackknife;
  capped.covariance_jackknife_cap = 1.5;
  const double capped_x = polishOnPlanes(map, scan, Pose6::Zero(), capped).covariance(0, 0);
  EXPECT_GT(capped_x, a.covariance(0, 0));
  EXPECT_LT(capped_x, b.covariance(0, 0));
  std::printf("x sd: plain clustered %.2f mm, jackknife %.2f mm, capped at 1.5 %.2f mm\n",
              1e3 * std::sqrt(a.covariance(0, 0)), 1e3 * std::sqrt(b.covariance(0, 0)),
              1e3 * std::sqrt(capped_x));
}

// The lazy plane fits from two threads at once (the polish's parallel lookups): each thread
// sees exactly the planes one thread alone fits, both racing for the same voxels.
TEST(Parallel, PlaneMapFitsFromTwoThreadsAreTheSerialOnes) {
  const PointArray reference = makeScene(false, 2);
  const PlaneMap serial(reference, 0.25, 6, 0.1), shared(reference, 0.25, 6, 0.1);
  std::vector<Eigen::Vector3d> queries;
  for (std::size_t i = 0; i < reference.size(); i += 7) {
    queries.push_back(reference.point(i).cast<double>() + Eigen::Vector3d(0.05, -0.03, 0.02));
  }
  std::vector<std::vector<const LocalPlane*>> seen(2, std::vector<const LocalPlane*>(queries.size()));
  runOnThreads(2, 2, [&](int job, int) {
    for (std::size_t k = 0; k < queries.size(); ++k) seen[std::size_t(job)][k] = shared.planeAt(queries[k]);
  });
  int planes = 0;
  for (std::size_t k = 0; k < queries.size(); ++k) {
    const LocalPlane* expected = serial.planeAt(queries[k]);
    for (int job = 0; job < 2; ++job) {
      const LocalPlane* got = seen[std::size_t(job)][k];
      ASSERT_EQ(got == nullptr, expected == nullptr) << k;
      if (!got) continue;
      EXPECT_EQ(got->normal, expected->normal) << k;
      EXPECT_EQ(got->mean, expected->mean) << k;
    }
    planes += expected != nullptr;
  }
  EXPECT_GT(planes, int(queries.size()) / 2);
}

// The polish's pass over every point looks up the planes on two threads; the sums are then
// taken in the same order, so the result is bit for bit the one-thread result.
TEST(Parallel, PolishOnTwoThreadsEqualsOne) {
  const KnownPair one(false), two(false);  // each with its own, not yet fitted, planes
  ASSERT_GT(one.scan.size(), 4096u);       // several jobs of the parallel lookups
  Pose6 start = isometryToPose(one.truth);
  start.head<3>() += Eigen::Vector3d(0.08, -0.05, 0.02);
  start.tail<3>() += Eigen::Vector3d(0.003, -0.002, 0.01);
  const PolishResult a = polishOnPlanes(one.map, one.scan, start, PolishSettings{}, 1);
  const PolishResult b = polishOnPlanes(two.map, two.scan, start, PolishSettings{}, 2);
  ASSERT_TRUE(a.applied) << a.reason;
  EXPECT_EQ(a.pose, b.pose);
  EXPECT_EQ(a.covariance, b.covariance);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.correspondences, b.correspondences);
  EXPECT_LT((poseToIsometry(b.pose).translation() - one.truth.translation()).norm(), 0.002);
}

TEST(PlanePolish, ACorridorIsFlaggedAlongItsAxisAndNotMovedAlongIt) {
  const KnownPair known(true);
  Pose6 start = isometryToPose(known.truth);
  start[0] += 0.05;  // 5 cm along the corridor: nothing can tell
  start[1] += 0.03;  // 3 cm across it: the walls fix it
  const PolishResult r = polishOnPlanes(known.map, known.scan, start, PolishSettings{});
  ASSERT_TRUE(r.applied) << r.reason;
  EXPECT_TRUE(r.degenerate) << r.weak_ratio;
  EXPECT_GT(std::abs(r.weak_direction[0]), 0.9);  // along x
  EXPECT_NEAR(r.pose[1], isometryToPose(known.truth)[1], 0.003);
  EXPECT_NEAR(r.pose[0], start[0], 0.01);  // left where the cube stages put it
  // Its predicted standard deviation along the axis dwarfs the one across it.
  EXPECT_GT(r.covariance(0, 0), 100.0 * r.covariance(1, 1));
}

// Over-relaxation stretches steps that keep their direction: from a start 12 cm / 0.5 deg off it
// must land on the plain iteration's pose (the same fixed point). On this pair the trilinear
// objective's plain steps do not fall short (5 steps either way; 5 against 6 from 16 cm off),
// so the step counts are printed, not compared.
TEST(PlanePolish, OverRelaxationReachesThePlainPose) {
  const KnownPair known(false);
  PolishSettings plain;
  plain.max_overrelaxation = 1.0;
  plain.max_iterations = 100;
  plain.round_steps = 0;  // one set of points per round: the steps compared are on the same set
  PolishSettings relaxed = plain;
  relaxed.max_overrelaxation = 2.0;
  Pose6 start = isometryToPose(known.truth);
  start.head<3>() += Eigen::Vector3d(0.10, -0.06, 0.03);
  start.tail<3>() += Eigen::Vector3d(0.002, -0.002, 0.008);
  const PolishResult a = polishOnPlanes(known.map, known.scan, start, plain);
  const PolishResult b = polishOnPlanes(known.map, known.scan, start, relaxed);
  ASSERT_TRUE(a.applied) << a.reason;
  ASSERT_TRUE(b.applied) << b.reason;
  const Eigen::Isometry3d ta = poseToIsometry(a.pose), tb = poseToIsometry(b.pose);
  EXPECT_LT((ta.translation() - tb.translation()).norm(), 1e-3);
  EXPECT_LT(rad2deg(Eigen::AngleAxisd(ta.linear() * tb.linear().transpose()).angle()), 0.01);
  EXPECT_LT((tb.translation() - known.truth.translation()).norm(), 0.002);
  std::printf("polish steps from 12 cm / 0.5 deg off: %d plain, %d over-relaxed\n", a.iterations,
              b.iterations);
}

// A round of the polish iterates on the points it collected at its start; round_steps makes it
// collect them again after that many steps without converging. From a start 12 cm / 0.6 deg
// off, where the first round needs more steps than that, collecting again every 3 or 8 steps
// must end on the pose of rounds that end only when they converge (the same fixed point,
// collected at the result), within the iteration budget.
TEST(PlanePolish, CollectingThePointsAgainKeepsTheFixedPoint) {
  const KnownPair known(false);
  Pose6 start = isometryToPose(known.truth);
  start.head<3>() += Eigen::Vector3d(0.10, -0.06, 0.03);
  start.tail<3>() += Eigen::Vector3d(0.002, -0.004, 0.008);
  PolishSettings s;
  s.max_iterations = 60;
  s.round_steps = 0;
  const PolishResult whole = polishOnPlanes(known.map, known.scan, start, s);
  ASSERT_TRUE(whole.applied) << whole.reason;
  ASSERT_GT(whole.iterations, 3);  // the first round needs more steps than the shortest rounds
  for (const int steps : {3, 8}) {
    s.round_steps = steps;
    const PolishResult r = polishOnPlanes(known.map, known.scan, start, s);
    ASSERT_TRUE(r.applied) << r.reason;
    EXPECT_LT(r.iterations, s.max_iterations) << steps;
    const Eigen::Isometry3d a = poseToIsometry(whole.pose), b = poseToIsometry(r.pose);
    EXPECT_LT((a.translation() - b.translation()).norm(), 3e-4) << steps;
    EXPECT_LT(rad2deg(Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle()), 0.003)
        << steps;
    EXPECT_LT((b.translation() - known.truth.translation()).norm(), 0.005) << steps;
  }
}

// Trilinear correspondences make the objective continuous in the pose: polishes started up to
// 3 cm / 0.3 deg apart must end on one pose (one plane per point, each point's own voxel, gives
// a piecewise objective whose steps stop 2-6 mm apart: docs/experiments.md).
TEST(PlanePolish, TrilinearCorrespondencesEndOnOnePoseFromEveryStart) {
  const KnownPair known(false);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Isometry3d> ends;
  for (int k = 0; k < 12; ++k) {
    Pose6 start = isometryToPose(known.truth);
    for (int i = 0; i < 3; ++i) start[i] += 0.03 * u(rng);
    for (int i = 3; i < 6; ++i) start[i] += deg2rad(0.3) * u(rng);
    const PolishResult r = polishOnPlanes(known.map, known.scan, start, PolishSettings{});
    EXPECT_TRUE(r.applied) << r.reason;
    ends.push_back(poseToIsometry(r.pose));
  }
  double max_t = 0.0, max_deg = 0.0;
  for (const Eigen::Isometry3d& a : ends) {
    for (const Eigen::Isometry3d& b : ends) {
      max_t = std::max(max_t, (a.translation() - b.translation()).norm());
      max_deg = std::max(max_deg, rad2deg(Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle()));
    }
  }
  EXPECT_LT(max_t, 3e-4);
  EXPECT_LT(max_deg, 0.003);
  RecordProperty("spread_mm", std::to_string(max_t * 1e3));
  std::printf("polish end spread over 12 starts: %.3f mm / %.4f deg\n", max_t * 1e3, max_deg);
}

TEST(PlanePolish, RefusesToMoveFurtherThanItsMaxShift) {
  const KnownPair known(false);
  Pose6 start = isometryToPose(known.truth);
  start.head<3>() += Eigen::Vector3d(0.04, -0.03, 0.02);  // 5.4 cm off
  PolishSettings s;
  s.max_shift_m = 0.03;
  const PolishResult r = polishOnPlanes(known.map, known.scan, start, s);
  EXPECT_FALSE(r.applied);
  EXPECT_EQ(r.reason, "the polish left the cube result's basin");
  EXPECT_EQ(r.pose, start);            // the cube result is kept
  EXPECT_GT(r.shift_m, s.max_shift_m);  // and the shift that was refused is reported
  s.max_shift_m = PolishSettings().max_shift_m;
  s.max_shift_rad = deg2rad(0.01);  // the rotation bound alone refuses it too
  start.tail<3>() += Eigen::Vector3d(0.0, 0.0, 0.002);
  EXPECT_FALSE(polishOnPlanes(known.map, known.scan, start, s).applied);
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
  s = PolishSettings{};
  s.max_overrelaxation = 0.5;  // a shrunk step
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.max_overrelaxation = 5.0;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.max_overrelaxation = 1.0;
  EXPECT_NO_THROW(validate(s));
  s.covariance_jackknife_cap = -1.0;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.covariance_jackknife_cap = std::nan("");
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.covariance_jackknife_cap = 10.0;
  EXPECT_NO_THROW(validate(s));
  s.round_steps = -1;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.round_steps = 101;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.round_steps = 0;  // rounds end only when they converge
  EXPECT_NO_THROW(validate(s));
  s.covariance_scale = 0.5;
  s.enabled = false;  // not checked when off
  EXPECT_NO_THROW(validate(s));
}
