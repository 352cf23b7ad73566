// Compass search: climbs to the step resolution, keeps its budget, validates.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "cube_scan_matcher/core/compass_search.h"

using namespace cube_scan_matcher;

TEST(CompassSearch, ClimbsASmoothPeakToTheStepResolution) {
  Vector6d peak;
  peak << 0.3, -0.2, 0.1, 0.02, -0.01, 0.03;
  auto f = [&](const Vector6d& x) { return -(x - peak).squaredNorm(); };
  CompassSettings s;
  s.levels = 10;
  const CompassResult r = compassMaximize(f, Vector6d::Zero(), s);
  EXPECT_LT((r.best - peak).norm(), 1e-3);
  EXPECT_GT(r.moves, 0);
  EXPECT_GE(r.best_value, r.initial_value);
}

TEST(CompassSearch, RespectsTheEvaluationBudgetAndValidates) {
  int calls = 0;
  CompassSettings s;
  s.max_evaluations = 17;
  compassMaximize([&](const Vector6d& x) { ++calls; return x.sum(); }, Vector6d::Zero(), s);
  EXPECT_EQ(calls, 17);
  s.levels = 0;
  EXPECT_THROW(compassMaximize([](const Vector6d&) { return 0.0; }, Vector6d::Zero(), s),
               std::invalid_argument);
}
