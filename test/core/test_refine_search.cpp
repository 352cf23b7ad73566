// The refine stage: distinct candidates, and the compass search that keeps the best of them.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/core/refine_search.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(RefineSearch, DistinctCandidatesSkipPosesCloseToAKeptOne) {
  RefineSettings s;
  Pose6 a = Pose6::Zero(), near_a = a, b = a, c = a, d = a;
  near_a[0] = 0.05;               // within 0.1 m of a
  b[0] = 0.3;                     // 0.3 m away
  c[5] = deg2rad(2.0);            // 2 deg away
  d[1] = -0.5;
  const double t = s.distinct_translation, r = s.distinct_rotation;
  EXPECT_EQ(distinctIndices({a, near_a, b, c, d}, t, r, 3), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(distinctIndices({a, near_a, b, c, d}, t, r, 10), (std::vector<int>{0, 2, 3, 4}));
  EXPECT_EQ(distinctIndices({a, b}, t, r, 1), (std::vector<int>{0}));
  // Indices already kept come first and exclude their neighbours.
  EXPECT_EQ(distinctIndices({a, near_a, b, c, d}, t, r, 10, {2}), (std::vector<int>{2, 0, 3, 4}));
}

TEST(RefineSearch, ClimbsFromEachCandidateAndKeepsTheBest) {
  const PointArray ref = cornerScene(8000, 4);
  Pose6 truth = Pose6::Zero();
  truth << 0.3, 0.2, -0.05, 0.0, 0.01, deg2rad(3);
  const PointArray scan = transformed(ref, poseToIsometry(truth).inverse());
  CubeGridSettings fs = edge(0.25);
  const CubeGrid coarse_grid = CubeGrid::build(ref, edge(0.5)), fine = CubeGrid::build(ref, fs);
  // One objective per thread, each on its own working copies.
  CoincidenceObjective c0(coarse_grid, scan), c1(coarse_grid, scan), f0(fine, scan), f1(fine, scan);
  const Eigen::Vector3d pivot = centroid(scan);
  std::vector<MultiScaleObjective> objectives;
  objectives.emplace_back(std::vector<CoincidenceObjective*>{&f0}, &c0, 3.0, pivot);
  objectives.emplace_back(std::vector<CoincidenceObjective*>{&f1}, &c1, 3.0, pivot);

  Pose6 near = truth, far = truth;
  near[0] += 0.12;               // a cube of E/2 off: the compass climbs back
  far.head<3>() += Eigen::Vector3d(2.0, -2.0, 0.0);  // another basin
  const RefineResult r = refineCandidates(objectives, {far, near}, CompassSettings{}, 2);
  EXPECT_LT((r.pose.head<3>() - truth.head<3>()).norm(), 0.06);
  EXPECT_LT(std::abs(r.pose[5] - truth[5]), deg2rad(0.5));
  EXPECT_DOUBLE_EQ(r.value, objectives[0](objectives[0].variable(r.pose)));
  EXPECT_GT(r.evaluations, 2 * 12);
  EXPECT_THROW(refineCandidates(objectives, {}, CompassSettings{}, 2), std::invalid_argument);
}

TEST(RefineSearch, SettingsAreValidatedOnlyWhenEnabled) {
  RefineSettings s;
  s.edge_fraction = 1.5;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.enabled = false;
  EXPECT_NO_THROW(validate(s));
  s = RefineSettings{};
  s.distinct_rotation = 0.0;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s = RefineSettings{};
  s.grids = 9;
  EXPECT_THROW(validate(s), std::invalid_argument);
}
