// The planar grid search: J over x, y and yaw around a centre; its local maxima seed the coarse
// starts.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/coarse_search.h"
#include "cube_scan_matcher/core/planar_grid.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

namespace {

PlanarGridSettings grid(double half_m, double half_yaw_deg) {
  PlanarGridSettings g;
  g.half_width_m = half_m;
  g.half_yaw = deg2rad(half_yaw_deg);
  return g;
}

/// A corner scene and its scan turned 30 deg on the spot and moved 1 m (`truth`), with two
/// objectives bound to it (two threads' working copies).
struct TurnedScan {
  PointArray ref = cornerScene(6000, 1);
  CubeGrid cubes = CubeGrid::build(ref, edge(0.5));
  Pose6 truth = (Pose6() << 1.0, -0.5, 0.0, 0.0, 0.0, deg2rad(30)).finished();
  PointArray scan = transformed(ref, poseToIsometry(truth).inverse());
  CoincidenceObjective a{cubes, scan}, b{cubes, scan};
};

}  // namespace

// A scan turned 30 deg on the spot and moved 1 m: far outside one GNMM's restart bounds
// (+-8 deg), on the grid: its best maximum is the grid pose nearest the truth.
TEST(PlanarGrid, BestMaximumIsTheGridPoseNearestTheTruth) {
  TurnedScan t;
  CoincidenceObjective &a = t.a, &b = t.b;
  const PlanarGridSettings g = grid(1.5, 45);
  EXPECT_EQ(g.poses(), 13 * 13 * 31);
  const PlanarGridResult two = planarGridMaxima({&a, &b}, g, Pose6::Zero(), 3, 2);
  ASSERT_FALSE(two.maxima.empty());
  EXPECT_EQ(two.evaluations, g.poses());
  EXPECT_NEAR(two.maxima[0][0], 1.0, 1e-9);
  EXPECT_NEAR(two.maxima[0][1], -0.5, 1e-9);
  EXPECT_NEAR(two.maxima[0][5], deg2rad(30), 1e-9);
  // J on the grid (the scan rotated once per yaw) is J as evaluate() counts it, at every
  // maximum; they come best first.
  for (std::size_t k = 0; k < two.maxima.size(); ++k) {
    EXPECT_EQ(two.maxima_J[k], a(two.maxima[k])) << "maximum " << k;
    if (k > 0) {
      EXPECT_LE(two.maxima_J[k], two.maxima_J[k - 1]);
    }
  }
  Pose6 off_centre = Pose6::Zero();
  off_centre << 0.13, -0.07, 0.02, 0.01, -0.005, deg2rad(1.3);
  const PlanarGridResult off = planarGridMaxima({&a, &b}, g, off_centre, 40, 2);
  ASSERT_GE(off.maxima.size(), 3u);
  for (std::size_t k = 0; k < off.maxima.size(); ++k) {
    EXPECT_EQ(off.maxima_J[k], b(off.maxima[k])) << "maximum " << k;
  }
  // The result does not depend on the thread count.
  const PlanarGridResult one = planarGridMaxima({&a}, g, Pose6::Zero(), 3, 1);
  EXPECT_EQ(one.maxima_J, two.maxima_J);
  ASSERT_EQ(one.maxima.size(), two.maxima.size());
  for (std::size_t k = 0; k < one.maxima.size(); ++k) EXPECT_EQ(one.maxima[k], two.maxima[k]);
}

// The grid's maxima seed the starts after the first: start 0 from the guess stays where the
// truth is out of reach, a seeded start finds it.
TEST(PlanarGrid, SeedsTheCoarseStartsAfterTheFirst) {
  TurnedScan t;
  CoincidenceObjective &a = t.a, &b = t.b;
  const Pose6& truth = t.truth;
  SearchSettings search;
  search.starts = 2;
  search.grid = grid(1.5, 45);
  const PlanarGridResult g = planarGridMaxima({&a, &b}, search.grid, Pose6::Zero(), 1, 2);
  ASSERT_EQ(g.maxima.size(), 1u);
  GnmmSettings gnmm;
  gnmm.max_iterations = 150;
  const CoarseSearchResult r = coarseSearch({&a, &b}, gnmm, search, Pose6::Zero(), g.maxima);
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_EQ(r.J_guess, a(Pose6::Zero())) << "start 0 runs from the guess";
  EXPECT_TRUE(posesWithin(r.runs[0].best, truth, 0.1, deg2rad(1.0)))
      << r.runs[0].best.transpose();
}

TEST(PlanarGrid, OffByDefaultAndSettingsAreValidatedByName) {
  EXPECT_FALSE(PlanarGridSettings{}.enabled());
  EXPECT_EQ(PlanarGridSettings{}.poses(), 1);
  EXPECT_NO_THROW(validate(PlanarGridSettings{}));
  auto refusedNaming = [](const PlanarGridSettings& g, const std::string& name) {
    try {
      validate(g);
      ADD_FAILURE() << "accepted: " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  refusedNaming(grid(-1.0, 45), "half_width_m");
  refusedNaming(grid(2.0, 200), "half_yaw");
  PlanarGridSettings g = grid(2.0, 45);
  g.step_m = 0.0;
  refusedNaming(g, "step_m");
  g = grid(2.0, 45);
  g.step_yaw = 0.0;
  refusedNaming(g, "step_yaw");
  refusedNaming(grid(20.0, 180), "poses");
  SearchSettings s;
  s.grid = grid(2.0, 200);
  EXPECT_THROW(validate(s), std::invalid_argument);
}

// The finest grid the ranges allow counts its poses without overflow, and is refused.
TEST(PlanarGrid, TheFinestGridIsCountedAndRefused) {
  PlanarGridSettings g = grid(20.0, 180.0);
  g.step_m = 0.05;
  g.step_yaw = deg2rad(0.1);
  EXPECT_EQ(g.poses(), std::int64_t(801) * 801 * 3601);
  EXPECT_THROW(validate(g), std::invalid_argument);
}
