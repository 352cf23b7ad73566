#include <gtest/gtest.h>

#include <cmath>

#include "cube_scan_matcher/core/gnmm.h"

using namespace cube_scan_matcher;

namespace {
const Vector6d kOptimum = (Vector6d() << 0.7, -0.4, 0.2, 0.1, -0.05, 0.12).finished();
Vector6d distantStart() { return kOptimum + (Vector6d() << 0.8, -0.7, 0.6, -0.12, 0.1, -0.13).finished(); }

// The paper's GNMM (15 vertices, 500 iterations) with the given restart half-widths.
GnmmSettings bounds(double t, double a) {
  GnmmSettings s;
  s.max_iterations = 500;
  s.bounds << t, t, t, a, a, a;
  return s;
}
}  // namespace

TEST(Gnmm, MaximisesASmoothFunctionFromADistantStart) {
  const auto f = [](const Vector6d& x) { return -(x - kOptimum).squaredNorm(); };
  const GnmmResult r = Gnmm(bounds(1.0, 0.15)).maximize(f, distantStart());
  EXPECT_LT((r.best - kOptimum).norm(), 1e-3);
  EXPECT_GT(r.best_value, r.initial_value);
  EXPECT_EQ(r.iterations, 500);
  EXPECT_GE(r.evaluations, 15 + 500);
}

TEST(Gnmm, MaximisesAnIntegerPlateauFunction) {
  // Integer-valued with flat terraces, like J: 100 - sum of floor(|x - x*| / step).
  const auto f = [](const Vector6d& x) {
    double v = 100;
    for (int k = 0; k < 6; ++k) v -= std::floor(std::abs(x[k] - kOptimum[k]) / (k < 3 ? 0.05 : 0.01));
    return v;
  };
  const GnmmResult r = Gnmm(bounds(1.0, 0.15)).maximize(f, distantStart());
  EXPECT_EQ(r.best_value, 100.0);
  EXPECT_LT((r.best.head<3>() - kOptimum.head<3>()).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_LT((r.best.tail<3>() - kOptimum.tail<3>()).cwiseAbs().maxCoeff(), 0.01);
}

TEST(Gnmm, EscapesALocalMaximumThroughRestarts) {
  // A narrow global peak next to a broad local one at the start, both terraced into integer
  // steps like J. (On a *smooth* local peak every contraction improves the worst vertex, so
  // GNMM never restarts: its restarts are triggered by plateaus, which J has everywhere.)
  const auto f = [](const Vector6d& x) {
    const double local = 1.0 * std::exp(-x.squaredNorm() / 0.5);
    const double global = 2.0 * std::exp(-(x - kOptimum).squaredNorm() / 0.2);
    return std::floor(20.0 * (local + global));
  };
  const GnmmResult r = Gnmm(bounds(1.0, 0.2)).maximize(f, Vector6d::Zero());
  EXPECT_GE(r.best_value, 38.0);
  EXPECT_GT(r.restarts, 0);
}

TEST(Gnmm, IsReproducibleWithAFixedSeed) {
  const auto f = [](const Vector6d& x) { return -std::floor((x - kOptimum).squaredNorm() * 100); };
  GnmmSettings s = bounds(1.0, 0.15);
  s.seed = 7;
  const GnmmResult a = Gnmm(s).maximize(f, distantStart());
  const GnmmResult b = Gnmm(s).maximize(f, distantStart());
  EXPECT_EQ(a.best, b.best);
  EXPECT_EQ(a.evaluations, b.evaluations);
  s.seed = 8;
  const GnmmResult c = Gnmm(s).maximize(f, distantStart());
  EXPECT_NE(a.best, c.best);
}

TEST(Gnmm, SettingsOutOfRangeAreRefused) {
  GnmmSettings s;
  s.vertices = 6;
  EXPECT_THROW(Gnmm{s}, std::invalid_argument);
  s = GnmmSettings{};
  s.bounds[4] = 0;
  EXPECT_THROW(Gnmm{s}, std::invalid_argument);
  s = GnmmSettings{};
  s.max_iterations = 0;
  EXPECT_THROW(Gnmm{s}, std::invalid_argument);
  s = GnmmSettings{};
  s.screen_iterations = s.max_iterations + 1;
  EXPECT_THROW(Gnmm{s}, std::invalid_argument);
}

// Screening: the first iterations climb a cheap, coarser version of f (its terraces 4x wider,
// as J on a quarter of the points), the last ones f itself. The result and J at the start are
// f's values, the screened iterations cost the screen's evaluations, and the optimum is found
// to f's own resolution.
TEST(Gnmm, ScreensOnACheapObjectiveThenClimbsTheObjective) {
  int f_calls = 0, screen_calls = 0;
  const auto terraces = [](const Vector6d& x, double width) {
    double v = 100;
    for (int k = 0; k < 6; ++k) v -= std::floor(std::abs(x[k] - kOptimum[k]) / ((k < 3 ? 0.05 : 0.01) * width));
    return v;
  };
  const Objective6 f = [&](const Vector6d& x) { return ++f_calls, terraces(x, 1.0); };
  const Objective6 screen = [&](const Vector6d& x) { return ++screen_calls, terraces(x, 4.0); };
  GnmmSettings s = bounds(1.0, 0.15);
  s.screen_iterations = 400;  // of 500
  const GnmmResult r = Gnmm(s).maximize(screen, f, distantStart());
  EXPECT_EQ(r.best_value, 100.0);
  EXPECT_EQ(r.best_value, terraces(r.best, 1.0));
  EXPECT_EQ(r.initial_value, terraces(distantStart(), 1.0));
  EXPECT_LT((r.best.head<3>() - kOptimum.head<3>()).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_LT((r.best.tail<3>() - kOptimum.tail<3>()).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_EQ(f_calls + screen_calls, r.evaluations);
  EXPECT_GT(screen_calls, 3 * f_calls);  // most of the work on the screen
  // Without screening iterations, the screen is never called.
  s.screen_iterations = 0;
  screen_calls = 0;
  Gnmm(s).maximize(screen, f, distantStart());
  EXPECT_EQ(screen_calls, 0);
}
