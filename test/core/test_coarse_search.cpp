// The coarse stage: independent GNMM starts, ranked by J, each the GNMM run of its own seed.
#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/core/coarse_search.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(CoarseSearch, RanksTheStartsByJAndEachIsTheGnmmRunOfItsSeed) {
  const PointArray ref = cornerScene(6000, 1);
  const CubeGrid grid = CubeGrid::build(ref, edge(0.5));
  Pose6 truth = Pose6::Zero();
  truth << 0.4, -0.3, 0.05, 0.01, -0.02, deg2rad(6);
  const PointArray scan = transformed(ref, poseToIsometry(truth).inverse());
  CoincidenceObjective a(grid, scan), b(grid, scan);
  GnmmSettings gnmm;
  gnmm.max_iterations = 150;
  SearchSettings search;
  search.starts = 3;
  search.threads = 2;
  const CoarseSearchResult r = coarseSearch({&a, &b}, gnmm, search, Pose6::Zero());

  ASSERT_EQ(r.runs.size(), 3u);
  EXPECT_GE(r.runs[0].best_value, r.runs[1].best_value);
  EXPECT_GE(r.runs[1].best_value, r.runs[2].best_value);
  EXPECT_EQ(r.J_guess, a(Pose6::Zero()));
  // Each run is exactly the GNMM of seed + k (whichever thread ran it), and the sums add up.
  int evaluations = 0, iterations = 0;
  for (int k = 0; k < 3; ++k) {
    GnmmSettings gs = gnmm;
    gs.seed += std::uint64_t(k);
    const GnmmResult g = Gnmm(gs).maximize([&a](const Vector6d& p) { return double(a(p)); },
                                           Pose6::Zero());
    evaluations += g.evaluations;
    iterations += g.iterations;
    int found = 0;
    for (const GnmmResult& run : r.runs) found += run.best == g.best;
    EXPECT_GE(found, 1) << "start " << k;
  }
  EXPECT_EQ(r.evaluations, evaluations);
  EXPECT_EQ(r.iterations, iterations);
  // From a 0.5 m / 6 deg error on a clean scene, the best start is within half a cube of the
  // truth.
  const double off = (r.runs[0].best.head<3>() - truth.head<3>()).norm();
  std::printf("[ best     ] %.3f m from the truth\n", off);
  EXPECT_LT(off, 0.25);
}

TEST(CoarseSearch, NeedsAnObjectivePerThreadAndValidSettings) {
  const PointArray ref = cornerScene(600, 2);
  const CubeGrid grid = CubeGrid::build(ref, edge(0.5));
  CoincidenceObjective a(grid, ref);
  SearchSettings search;
  search.starts = 4;
  search.threads = 2;
  EXPECT_THROW(coarseSearch({&a}, GnmmSettings{}, search, Pose6::Zero()), std::invalid_argument);
  search.starts = 0;
  EXPECT_THROW(validate(search), std::invalid_argument);
  search.starts = 4;
  search.threads = 65;
  EXPECT_THROW(validate(search), std::invalid_argument);
}
