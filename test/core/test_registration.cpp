// Registration against known transforms on synthetic scenes sampled like the paper's tilting
// scanner (eq. 1, +-4 cm range noise): perturbed starts within the paper's big bounds
// (+-1 m, +-8 deg), both directions, translation and angle tolerances.
#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <thread>
#include <vector>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/core/simd_path.h"
#include "simd_test_paths.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

namespace {

struct Scans {
  PointArray first, second;
  Eigen::Isometry3d T_first_second;  // second-scan points -> first-scan frame (the truth)
};

// Two sweeps of the same scene from sensor poses 2.5 m and 12 deg of yaw apart. The first pose
// has a yaw of 17 deg and a little roll and pitch: a robot is never exactly aligned with the
// walls of a procedural world, and a scene whose planes are parallel to the cube grid is a
// degenerate case for any grid method (J is flat within a cube).
Scans makeScans(sim::SceneType type, std::uint64_t seed) {
  const sim::Scene scene = sim::Scene::generate(type, seed);
  const sim::ScannerModel model;
  Eigen::Isometry3d body1 = Eigen::Isometry3d::Identity(), body2 = Eigen::Isometry3d::Identity();
  body1.translation() = Eigen::Vector3d(5, 0.3, scene.groundHeight(5, 0.3) + 1.0);
  body1.linear() = rotationFromRpy(0.012, -0.02, deg2rad(17));
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation() = Eigen::Vector3d(2.4, 0.6, 0.0);
  step.linear() = rotationFromRpy(0.02, -0.015, deg2rad(12));
  body2 = body1 * step;
  body2.translation().z() = scene.groundHeight(body2.translation().x(), body2.translation().y()) + 1.05;
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  std::mt19937_64 rng(seed);
  Scans s;
  s.first = sim::scan(scene, model, body1 * mount, rng);
  s.second = sim::scan(scene, model, body2 * mount, rng);
  s.T_first_second = (body1 * mount).inverse() * (body2 * mount);
  return s;
}

enum class Mode { Default, Paper, BitCopies };

std::string toString(Mode m) {
  switch (m) {
    case Mode::Default: return "default";
    case Mode::Paper: return "paper";
    case Mode::BitCopies: return "bitcopies";
  }
  return "unknown";
}

/// The shipped settings, the paper's fixed mode, and the shipped settings counting on bit
/// copies of V (as grids above max_byte_cubes do).
RegistrationSettings settingsFor(Mode m) {
  RegistrationSettings s = m == Mode::Paper ? RegistrationSettings::paper() : RegistrationSettings{};
  if (m == Mode::BitCopies) s.grid.max_byte_cubes = 0;
  return s;
}

/// Bounds [m, deg]: at least `min_successes` of the 6 trials within trial_m / trial_deg, and
/// the (upper) median within median_m / median_deg, each near twice the measured figure. The
/// package's modes: every trial within 6 mm / 0.011 deg (measured), so within 12 mm /
/// 0.025 deg. The paper's mode (one GNMM of 500 iterations on E = 0.5 m cubes, no refine)
/// lands in a wrong local maximum in a part of the trials from these big errors (measured: 1-6
/// of 6 per case within 0.25 m / 2 deg, 28 of 48 in all, the worst case's median 0.77 m /
/// 0.90 deg; on the real corridor pairs 16/25 and 0/25, docs/experiments.md, "The first
/// real-pair runs"): for it the test guards that it still converges in some trials and in the
/// median improves on the start (about 1 m off).
struct Tolerance {
  int min_successes;
  double trial_m, trial_deg, median_m, median_deg;
};
Tolerance toleranceFor(Mode m) {
  return m == Mode::Paper ? Tolerance{1, 0.25, 2.0, 0.9, 2.0}
                          : Tolerance{6, 0.012, 0.025, 0.012, 0.025};
}

using Case = std::tuple<Mode, sim::SceneType, bool>;  // bool: register first -> second

class SyntheticRegistration : public ::testing::TestWithParam<Case> {};

// From the paper's *big* initial errors (+-1 m, +-8 deg per parameter), both directions, all
// four scenes, in each mode: the trials and the median within the mode's tolerance, and J
// never below J at the guess. (Bit copies give the default's results exactly.)
TEST_P(SyntheticRegistration, RecoversKnownTransformFromBigInitialErrors) {
  const auto [mode, scene, reverse] = GetParam();
  const Scans s = makeScans(scene, 11);
  const PointArray& ref = reverse ? s.second : s.first;
  const PointArray& scan = reverse ? s.first : s.second;
  const Eigen::Isometry3d truth = reverse ? s.T_first_second.inverse() : s.T_first_second;
  ASSERT_GT(scan.size(), 20000u);
  const Tolerance tol = toleranceFor(mode);

  CubeRegistration reg(settingsFor(mode));
  reg.setReference(ref);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Pose6 truth_pose = isometryToPose(truth);
  std::vector<double> dts, das;
  int successes = 0;
  for (int trial = 0; trial < 6; ++trial) {
    Pose6 guess = truth_pose;
    for (int k = 0; k < 3; ++k) guess[k] += 1.0 * u(rng);
    for (int k = 3; k < 6; ++k) guess[k] += deg2rad(8.0) * u(rng);
    const RegistrationResult r = reg.align(scan, guess);
    ASSERT_TRUE(r.ok()) << r.message;
    const Eigen::Isometry3d err = truth.inverse() * r.transform;
    const double dt = (r.transform.translation() - truth.translation()).norm();
    const double da = rad2deg(Eigen::AngleAxisd(err.linear()).angle());
    std::printf("[ trial    ] %s %s %d: %.3f m %.3f deg, %s\n", toString(mode).c_str(),
                sim::toString(scene).c_str(), trial, dt, da, r.message.c_str());
    successes += dt < tol.trial_m && da < tol.trial_deg;
    EXPECT_GE(r.J, r.J_guess);
    dts.push_back(dt);
    das.push_back(da);
  }
  EXPECT_GE(successes, tol.min_successes)
      << "trials within " << tol.trial_m << " m and " << tol.trial_deg << " deg";
  std::nth_element(dts.begin(), dts.begin() + 3, dts.end());
  std::nth_element(das.begin(), das.begin() + 3, das.end());
  EXPECT_LT(dts[3], tol.median_m);
  EXPECT_LT(das[3], tol.median_deg);
}

INSTANTIATE_TEST_SUITE_P(
    ModesAndScenes, SyntheticRegistration,
    ::testing::Combine(::testing::Values(Mode::Default, Mode::Paper, Mode::BitCopies),
                       ::testing::Values(sim::SceneType::Hall, sim::SceneType::Urban,
                                         sim::SceneType::Park, sim::SceneType::Natural),
                       ::testing::Bool()),
    [](const ::testing::TestParamInfo<Case>& i) {
      return toString(std::get<0>(i.param)) + "_" + sim::toString(std::get<1>(i.param)) +
             (std::get<2>(i.param) ? "_reverse" : "_forward");
    });

TEST(Registration, PaperModeRunsOneGnmmOfFiveHundredIterationsOnAllPoints) {
  const Scans s = makeScans(sim::SceneType::Urban, 3);
  CubeRegistration reg(RegistrationSettings::paper(0.5));
  reg.setReference(s.first);
  Pose6 guess = isometryToPose(s.T_first_second);
  guess.head<3>() += Eigen::Vector3d(0.8, -0.6, 0.3);
  guess[5] += deg2rad(-7);
  const RegistrationResult r = reg.align(s.second, guess);
  ASSERT_TRUE(r.ok());
  EXPECT_LT((r.transform.translation() - s.T_first_second.translation()).norm(), 0.10);
  EXPECT_EQ(r.iterations, 500);
  EXPECT_EQ(r.points_used, s.second.size());  // the paper evaluates every point
}

TEST(Registration, BadInputsGiveAResultThatSaysSo) {
  CubeRegistration reg(RegistrationSettings{});
  PointArray scan;
  scan.push_back(1, 2, 3);
  EXPECT_EQ(reg.align(scan, Pose6::Zero()).status, RegistrationStatus::NoReference);

  PointArray ref;
  for (int i = 0; i < 100; ++i) ref.push_back(float(i % 10), float(i / 10), 0.f);
  reg.setReference(ref);
  EXPECT_EQ(reg.align(PointArray{}, Pose6::Zero()).status, RegistrationStatus::EmptyScan);
  Pose6 nan_guess = Pose6::Zero();
  nan_guess[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(reg.align(ref, nan_guess).status, RegistrationStatus::InvalidGuess);
  nan_guess[4] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(reg.align(ref, nan_guess).status, RegistrationStatus::InvalidGuess);

  PointArray far_away;
  for (int i = 0; i < 100; ++i) far_away.push_back(500.f + float(i), 500.f, 500.f);
  const RegistrationResult r = reg.align(far_away, Pose6::Zero());
  EXPECT_EQ(r.status, RegistrationStatus::NoOverlap);
  EXPECT_NE(r.message.find("overlap"), std::string::npos);
}

TEST(Registration, FailedReferenceKeepsThePreviousOne) {
  CubeRegistration reg(RegistrationSettings{});
  PointArray ref;
  for (int i = 0; i < 100; ++i) ref.push_back(float(i % 10), float(i / 10), 0.f);
  reg.setReference(ref);
  const std::size_t l = reg.grid().occupiedCount();
  PointArray absurd = ref;
  absurd.push_back(1e7f, 1e7f, 1e7f);
  EXPECT_THROW(reg.setReference(absurd), CubeGridError);
  EXPECT_TRUE(reg.hasReference());
  EXPECT_EQ(reg.grid().occupiedCount(), l);
}

TEST(Registration, AReusedMatcherGivesTheResultsOfAFreshOne) {
  // The per-thread working copies outlive a reference: a matcher that has registered other
  // scans (other grid sizes) must give exactly what a fresh matcher gives.
  const Scans a = makeScans(sim::SceneType::Urban, 3), b = makeScans(sim::SceneType::Park, 4);
  Pose6 guess_a = isometryToPose(a.T_first_second), guess_b = isometryToPose(b.T_first_second);
  guess_a[0] += 0.4;
  guess_b[5] += deg2rad(3);
  CubeRegistration reused(RegistrationSettings{});
  reused.setReference(b.first);
  const RegistrationResult rb = reused.align(b.second, guess_b);
  reused.setReference(a.first);
  const RegistrationResult ra = reused.align(a.second, guess_a);
  for (int k = 0; k < 2; ++k) {
    CubeRegistration fresh(RegistrationSettings{});
    fresh.setReference(k ? b.first : a.first);
    const RegistrationResult f = fresh.align(k ? b.second : a.second, k ? guess_b : guess_a);
    const RegistrationResult& r = k ? rb : ra;
    EXPECT_EQ(r.J, f.J) << k;
    EXPECT_EQ(r.evaluations, f.evaluations) << k;
    EXPECT_TRUE(r.pose.isApprox(f.pose, 1e-12)) << k;
  }
  EXPECT_EQ(reused.score(a.second, ra.pose), ra.J);
}

TEST(Registration, EverySimdPathGivesTheSameResult) {
  // The vector paths compute the same indices, so a whole registration (search, refine,
  // polish, covariance) must come out bit-identical on each.
  const Scans a = makeScans(sim::SceneType::Urban, 5);
  Pose6 guess = isometryToPose(a.T_first_second);
  guess[1] -= 0.5;
  guess[5] += deg2rad(4);
  CubeRegistration reg(RegistrationSettings{});
  reg.setReference(a.first);
  std::optional<RegistrationResult> want;
  for (SimdPath path : simdPathsToCompare()) {
    setSimdPath(path);
    const RegistrationResult r = reg.align(a.second, guess);
    if (!want) {
      want = r;
      continue;
    }
    EXPECT_EQ(r.J, want->J) << simdPathName(path);
    EXPECT_EQ(r.evaluations, want->evaluations) << simdPathName(path);
    EXPECT_EQ(r.pose, want->pose) << simdPathName(path);
    EXPECT_EQ(r.covariance, want->covariance) << simdPathName(path);
  }
  setSimdPath(std::nullopt);
  ASSERT_TRUE(want.has_value());
  EXPECT_TRUE(poseError(poseToIsometry(want->pose), a.T_first_second).success());
}

TEST(Registration, ConcurrentAlignCallsGiveTheSequentialResults) {
  // align() shares the per-thread working copies, so calls on one instance are serialised:
  // two callers at once must get exactly what one caller gets.
  const Scans s = makeScans(sim::SceneType::Urban, 3);
  CubeRegistration reg(RegistrationSettings{});
  reg.setReference(s.first);
  Pose6 g1 = isometryToPose(s.T_first_second), g2 = g1;
  g1[0] += 0.5;
  g2[4] += deg2rad(4);
  const RegistrationResult a = reg.align(s.second, g1), b = reg.align(s.second, g2);
  RegistrationResult ca, cb;
  std::thread t1([&] { ca = reg.align(s.second, g1); });
  std::thread t2([&] { cb = reg.align(s.second, g2); });
  t1.join();
  t2.join();
  EXPECT_TRUE(ca.pose.isApprox(a.pose, 1e-12));
  EXPECT_TRUE(cb.pose.isApprox(b.pose, 1e-12));
  EXPECT_EQ(ca.J, a.J);
  EXPECT_EQ(cb.J, b.J);
}

TEST(Registration, SetReferenceWhileAligningIsSafe) {
  // align() used to read the reference before taking its lock, so a setReference() in another
  // thread could free the grids under a running registration (ThreadSanitizer reported it).
  const Scans a = makeScans(sim::SceneType::Urban, 3), b = makeScans(sim::SceneType::Park, 4);
  CubeRegistration reg(RegistrationSettings{});
  reg.setReference(a.first);
  const Pose6 guess = isometryToPose(a.T_first_second);
  std::thread swapper([&] {
    for (int k = 0; k < 6; ++k) reg.setReference(k % 2 ? a.first : b.first);
  });
  for (int k = 0; k < 6; ++k) {
    const RegistrationResult r = reg.align(a.second, guess);
    EXPECT_TRUE(r.ok()) << r.message;
    EXPECT_GT(r.reference_cubes, 0u);
  }
  swapper.join();
  reg.setReference(a.first);
  EXPECT_GT(reg.score(a.second, guess), 0);
}

TEST(Registration, SetSettingsWhileAligningIsSafe) {
  // What a dynamic_reconfigure change does during a registration: new settings from another
  // thread take effect at the next align(), never in the middle of one.
  const Scans a = makeScans(sim::SceneType::Urban, 3);
  CubeRegistration reg(RegistrationSettings{});
  reg.setReference(a.first);
  const Pose6 guess = isometryToPose(a.T_first_second);
  std::thread changer([&] {
    for (int k = 0; k < 6; ++k) {
      RegistrationSettings s;
      s.search.starts = 1 + k % 4;
      s.search.threads = 1 + k % 2;
      reg.setSettings(s);
    }
  });
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(reg.align(a.second, guess).ok());
  changer.join();
}

TEST(Registration, SettingsAreValidated) {
  RegistrationSettings s = RegistrationSettings{};
  s.collapse_fraction = 2.0;
  EXPECT_THROW(CubeRegistration{s}, std::invalid_argument);
  s = RegistrationSettings{};
  s.refine.enabled = true;
  s.refine.edge_fraction = 1.5;
  EXPECT_THROW(CubeRegistration{s}, std::invalid_argument);
  s = RegistrationSettings{};
  s.search.axis_probe_m = -0.5;
  EXPECT_THROW(CubeRegistration{s}, std::invalid_argument);
  s = RegistrationSettings{};
  s.search.axis_probe_gain = 2.0;
  EXPECT_THROW(CubeRegistration{s}, std::invalid_argument);
  s = RegistrationSettings{};
  s.coarse_max_points = -1;
  EXPECT_THROW(CubeRegistration{s}, std::invalid_argument);
}

// coarse_max_points: the coarse search evaluates no more points than the cap, J at the result
// still counts them all (as without the cap), and the known transform is recovered.
TEST(Registration, ACapOnTheCoarsePointsKeepsTheResult) {
  const Scans s = makeScans(sim::SceneType::Urban, 1);
  RegistrationSettings settings;
  CubeRegistration full(settings);
  full.setReference(s.first);
  const Pose6 truth = isometryToPose(s.T_first_second);
  Pose6 guess = truth;
  guess.head<3>() += Eigen::Vector3d(0.6, -0.5, 0.1);
  guess[5] += deg2rad(5.0);
  const RegistrationResult all = full.align(s.second, guess);
  ASSERT_GT(all.points_used, 3000u);
  settings.coarse_max_points = int(all.points_used / 3);
  CubeRegistration capped(settings);
  capped.setReference(s.first);
  const RegistrationResult r = capped.align(s.second, guess);
  EXPECT_EQ(r.points_used, std::size_t(settings.coarse_max_points));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.J, capped.score(s.second, r.pose));  // J on all points, not the cap's
  EXPECT_LT((r.transform.translation() - s.T_first_second.translation()).norm(), 0.02);
  EXPECT_LT(rad2deg(Eigen::AngleAxisd(r.transform.linear().transpose() * s.T_first_second.linear()).angle()), 0.1);
}

// Screening (screen_stride 4): the coarse search's early iterations on a quarter of the points
// find the known transform as the search without screening does; J and J at the guess count
// every coarse point.
TEST(Registration, ScreeningKeepsTheResult) {
  const Scans s = makeScans(sim::SceneType::Urban, 1);
  const Pose6 truth = isometryToPose(s.T_first_second);
  Pose6 guess = truth;
  guess.head<3>() += Eigen::Vector3d(0.6, -0.5, 0.1);
  guess[5] += deg2rad(5.0);
  RegistrationSettings settings;
  EXPECT_EQ(settings.screen_stride, 1);  // off by default
  settings.screen_stride = 4;
  CubeRegistration screened(settings);
  screened.setReference(s.first);
  settings.screen_stride = 1;
  CubeRegistration plain(settings);
  plain.setReference(s.first);
  const RegistrationResult a = screened.align(s.second, guess);
  const RegistrationResult b = plain.align(s.second, guess);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_GT(a.points_used, 4 * 500u);  // enough points to screen
  EXPECT_EQ(a.J_guess, b.J_guess);     // J at the guess on all coarse points
  EXPECT_EQ(a.J, screened.score(s.second, a.pose));
  for (const RegistrationResult* r : {&a, &b}) {
    EXPECT_LT((r->transform.translation() - s.T_first_second.translation()).norm(), 0.02);
    EXPECT_LT(rad2deg(Eigen::AngleAxisd(r->transform.linear().transpose() * s.T_first_second.linear()).angle()), 0.1);
  }
  EXPECT_LT((a.transform.translation() - b.transform.translation()).norm(), 0.005);
  // Screening iterations outside [0, iterations] are refused.
  settings.screen_stride = 0;
  EXPECT_THROW(CubeRegistration{settings}, std::invalid_argument);
  settings.screen_stride = 4;
  settings.screen_final_iterations = -1;
  EXPECT_THROW(CubeRegistration{settings}, std::invalid_argument);
}

}  // namespace

// The "no motion" maximum (dense_sampling.h): two sweeps 1.5 m apart along the street of a
// weakly structured world, guesses 0.9 m short of the motion (0.6 m from "no motion"). J on all
// points peaks where the second sweep is laid onto the first's own sampling pattern; a coarse
// search on densely sampled cubes only (dense_points = 4) finds the motion. (Measured when
// written: with dense_points = 0, 7 of these 8 trials land at "no motion", 1.5 m off; with 3,
// 4 or 6 all 8 within 4.2 cm.)
TEST(Registration, DenseSamplingFindsTheMotionNotTheSensorsOwnPattern) {
  for (const sim::SceneType type : {sim::SceneType::Hall, sim::SceneType::Park}) {
    const sim::Scene scene = sim::Scene::generate(type, 1);
    const sim::ScannerModel model;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int successes = 0;
    for (int trial = 0; trial < 4; ++trial) {
      const double x = 10.0 + 25.0 * trial;
      Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
      a.translation() = Eigen::Vector3d(x, 0.0, scene.groundHeight(x, 0.0) + 1.0);
      Eigen::Isometry3d b = a;
      b.translation() = Eigen::Vector3d(x + 1.5, 0.0, scene.groundHeight(x + 1.5, 0.0) + 1.0);
      const Eigen::Isometry3d truth = a.inverse() * b;
      RegistrationSettings settings;
      settings.dense_points = 4;
      CubeRegistration reg(settings);
      reg.setReference(sim::scanInBody(scene, model, a, rng));
      const PointArray scan = sim::scanInBody(scene, model, b, rng);
      Pose6 guess = isometryToPose(truth);
      guess[0] -= 0.9;
      guess[1] += 0.2 * u(rng);
      guess[5] += deg2rad(2.0) * u(rng);
      const RegistrationResult r = reg.align(scan, guess);
      const double dt = (r.transform.translation() - truth.translation()).norm();
      std::printf("[ trial    ] %s x=%.0f: %.3f m off, J %d, J at truth %d\n",
                  sim::toString(type).c_str(), x, dt, r.J, reg.score(scan, isometryToPose(truth)));
      successes += dt < 0.10;
    }
    EXPECT_EQ(successes, 4) << sim::toString(type);
  }
}

// A featureless tunnel (the scene benchmark's "tunnel"): nothing within the scanner's range
// fixes the position along its axis. The result must say so (degenerate, the weak axis along x,
// a standard deviation along it of decimetres or more), and the acceptance gate must refuse
// it, whatever the search did along the axis. (Measured when written: before the plane map's
// min_spread and the supported translation information, the polish gave the axis 0.5 % of the
// floor's information, a 1-2 cm sd, and results 0.2-1.9 m off were accepted.)
TEST(Registration, ATunnelIsFlaggedDegenerateAlongItsAxisAndRejected) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Tunnel, 1);
  const sim::ScannerModel model;
  std::mt19937_64 rng(5);
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), motion = Eigen::Isometry3d::Identity();
  a.translation() = Eigen::Vector3d(20.0, 0.4, 1.0);
  a.linear() = rotationFromRpy(0.0, 0.0, deg2rad(4.0));
  motion.translation() = Eigen::Vector3d(3.0, -0.5, 0.02);
  motion.linear() = rotationFromRpy(0.01, -0.01, deg2rad(-8.0));
  CubeRegistration reg{RegistrationSettings{}};
  reg.setReference(sim::scanInBody(scene, model, a, rng));
  const PointArray scan = sim::scanInBody(scene, model, a * motion, rng);
  for (const double off : {-0.6, 0.4}) {
    Pose6 guess = isometryToPose(motion);
    guess[0] += off;
    const RegistrationResult r = reg.align(scan, guess);
    ASSERT_TRUE(r.ok()) << r.message;
    ASSERT_TRUE(r.polished);
    // The axis in the reference frame: the tunnel's x turned by the start's -4 deg of yaw.
    const Eigen::Vector3d axis = a.linear().transpose() * Eigen::Vector3d::UnitX();
    EXPECT_TRUE(r.degenerate) << "translation weak ratio " << r.translation_weak_ratio;
    EXPECT_GT(std::abs(r.translation_weak_axis.dot(axis)), 0.95);
    EXPECT_GT(std::sqrt(axis.dot(r.covariance.topLeftCorner<3, 3>() * axis)), 0.1);
    // Across the axis the walls, floor and ceiling fix it.
    const Eigen::Vector3d across = r.transform.translation() - motion.translation();
    EXPECT_LT((across - across.dot(axis) * axis).norm(), 0.05);
    EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Degenerate);
    // Degenerate: the search ran again from new seeds (SearchSettings::retries), in vain.
    EXPECT_EQ(r.attempts, 1 + RegistrationSettings{}.search.retries);
    EXPECT_EQ(r.attempt_used, 0);
    EXPECT_EQ(r.J_axis, 0);  // no axis probe on a degenerate result: nothing to find along it
  }
  // A confirmed result is not searched again.
  const Scans s = makeScans(sim::SceneType::Urban, 3);
  CubeRegistration urban{RegistrationSettings{}};
  urban.setReference(s.first);
  const RegistrationResult u = urban.align(s.second, isometryToPose(s.T_first_second));
  EXPECT_TRUE(u.polished && !u.degenerate);
  EXPECT_EQ(u.attempts, 1);
  // The axis probe ran (its best J is at least the result's) and found nothing better.
  EXPECT_GE(u.J_axis, u.J);
  EXPECT_FALSE(u.axis_moved);
  // J before the polish is recorded; on a right result the polish costs few coincident cubes
  // (scene benchmark: median 0.2 %, p99 2.6 % of the accepted right results).
  EXPECT_GT(u.J_prepolish, 0);
  EXPECT_LE(std::abs(u.J - u.J_prepolish), 0.05 * u.J_prepolish);
}
