// SweepCutter: where the sweeps of a tilting 2D laser end (turning points, duration, stall, gap,
// time backwards, late lines, too few lines). Each test feeds lines through a Driver that keeps
// the line queue the way SweepAssemblerNodelet does and checks that it stays in step.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <random>
#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/assembly/sweep_cutter.h"

using namespace cube_scan_matcher;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Feeds lines (numbered 0, 1, ...) and keeps the queue as the nodelet does: the closed sweeps
/// as lists of line numbers, the discarded lines with their reasons.
struct Driver {
  SweepCutter cutter;
  std::deque<int> queue;
  std::vector<std::vector<int>> sweeps;
  std::vector<CutReason> sweep_reasons;
  std::vector<int> discarded;
  std::vector<CutReason> discard_reasons;  // one per discarded line
  int next = 0;

  explicit Driver(const SweepCutterSettings& s) : cutter(s) {}

  CutResult add(double t, std::optional<double> angle) {
    const int id = next++;
    const CutResult r = cutter.addLine(t, angle);
    if (r.line_kept) {
      queue.push_back(id);
    } else {
      discarded.push_back(id);
      discard_reasons.push_back(r.reason);
    }
    EXPECT_LE(r.closed_lines, queue.size());
    std::vector<int> closed(queue.begin(), queue.begin() + std::ptrdiff_t(r.closed_lines));
    queue.erase(queue.begin(), queue.begin() + std::ptrdiff_t(r.closed_lines));
    if (r.event == CutEvent::SweepEnded) {
      EXPECT_GT(r.closed_lines, 0u);
      sweeps.push_back(closed);
      sweep_reasons.push_back(r.reason);
    } else if (r.event == CutEvent::Discarded) {
      for (int c : closed) {
        discarded.push_back(c);
        discard_reasons.push_back(r.reason);
      }
    } else {
      EXPECT_EQ(r.closed_lines, 0u);
      EXPECT_TRUE(r.line_kept);
      EXPECT_EQ(r.reason, CutReason::None);
    }
    EXPECT_EQ(queue.size(), cutter.pendingLines()) << "queue out of step at line " << id;
    return r;
  }
};

/// Triangular tilt [rad]: from -amp at t = 0 up to +amp at t = half, down to -amp at 2 half...
double triangle(double t, double amp, double half) {
  const double phase = std::fmod(t, 2.0 * half) / half;  // [0, 2)
  return phase < 1.0 ? -amp + 2.0 * amp * phase : amp - 2.0 * amp * (phase - 1.0);
}

}  // namespace

TEST(SweepCutter, CutsATriangularTiltAtEachTurningPointExactlyOnce) {
  // 40 lines/s, +-30 deg, 4.5 s per half-period: 180 lines per half-period, turning points on
  // lines 180k (t = 4.5k s). Starts a quarter period in (line 90, mid-ramp).
  SweepCutterSettings s;
  Driver d(s);
  const double rate = 40.0, half = 4.5;
  const int first = 90, last = 5 * 180 + 20;  // turning points at lines 180, 360, ..., 900
  for (int k = first; k <= last; ++k) d.add(k / rate, triangle(k / rate, 30 * kDeg, half));
  // Turning points at 180, 360, 540, 720, 900: each is the last line of exactly one sweep.
  ASSERT_EQ(d.sweeps.size(), 5u);
  for (std::size_t i = 0; i < d.sweeps.size(); ++i) {
    EXPECT_EQ(d.sweep_reasons[i], CutReason::TurningPoint);
    EXPECT_EQ(d.sweeps[i].back() + first, 180 * int(i + 1)) << "sweep " << i;
    if (i > 0) {  // whole half-periods: the line after one turning point to the next one
      EXPECT_EQ(d.sweeps[i].front() + first, 180 * int(i) + 1);
      EXPECT_EQ(d.sweeps[i].size(), 180u);
    }
  }
  EXPECT_EQ(d.sweeps[0].front(), 0);  // the first sweep starts with the first line
  EXPECT_TRUE(d.discarded.empty());
  EXPECT_EQ(d.cutter.pendingLines(), std::size_t(last - 900));  // after the last turning point
}

TEST(SweepCutter, NoiseWithinTheHysteresisDoesNotCut) {
  SweepCutterSettings s;
  s.turn_hysteresis = 1.0 * kDeg;
  std::mt19937 rng(3);
  // Peak-to-peak noise 0.9 deg < 1 deg: no cut but at the turning points.
  std::uniform_real_distribution<double> noise(-0.45 * kDeg, 0.45 * kDeg);
  Driver d(s);
  const double rate = 40.0, half = 4.5;
  for (int k = 0; k <= 4 * 180 + 40; ++k) {
    d.add(k / rate, triangle(k / rate, 30 * kDeg, half) + noise(rng));
  }
  ASSERT_EQ(d.sweeps.size(), 4u);  // turning points at lines 180, 360, 540, 720
  for (std::size_t i = 0; i < d.sweeps.size(); ++i) {
    // 1/6 deg per line: noise can move the extreme by at most 0.9 / (1/6) < 6 lines.
    EXPECT_NEAR(d.sweeps[i].back(), 180 * int(i + 1), 6) << "sweep " << i;
  }
  // A tilt standing still with the same noise: no cut at all (stall detection off).
  s.stall_timeout = 0.0;
  Driver still(s);
  for (int k = 0; k < 2000; ++k) still.add(k / rate, 5 * kDeg + noise(rng));
  EXPECT_TRUE(still.sweeps.empty());
  EXPECT_TRUE(still.discarded.empty());
  // The same noise with a hysteresis below it does cut (the test can fail).
  s.turn_hysteresis = 0.3 * kDeg;
  Driver jittery(s);
  for (int k = 0; k < 2000; ++k) jittery.add(k / rate, 5 * kDeg + noise(rng));
  EXPECT_GT(jittery.sweeps.size() + jittery.discarded.size(), 0u);
}

TEST(SweepCutter, DurationModeCutsWithoutAngles) {
  SweepCutterSettings s;
  s.sweep_duration = 0.99;  // not 1.0: no rounding question at the cut
  Driver d(s);
  const double t0 = 1000.0;
  for (int k = 0; k < 40 * 5 + 3; ++k) d.add(t0 + k * 0.025, std::nullopt);
  ASSERT_EQ(d.sweeps.size(), 5u);
  for (std::size_t i = 0; i < d.sweeps.size(); ++i) {
    EXPECT_EQ(d.sweep_reasons[i], CutReason::Duration);
    EXPECT_EQ(d.sweeps[i].size(), 40u);  // [t0 + i, t0 + i + 1)
    EXPECT_EQ(d.sweeps[i].front(), 40 * int(i));
  }
  EXPECT_EQ(d.cutter.pendingLines(), 3u);
  // With a tilt as well, whichever comes first: a duration shorter than the half-period cuts
  // inside the ramps, and the turning points still cut.
  s.sweep_duration = 2.99;
  Driver both(s);
  for (int k = 0; k <= 360 + 20; ++k) both.add(k / 40.0, triangle(k / 40.0, 30 * kDeg, 4.5));
  std::vector<int> ends;
  for (const auto& sw : both.sweeps) ends.push_back(sw.back());
  EXPECT_EQ(ends, (std::vector<int>{119, 180, 300, 360}));
}

TEST(SweepCutter, AStalledTiltClosesTheSweepThenDiscardsLinesUntilItMoves) {
  SweepCutterSettings s;
  s.stall_timeout = 1.0;
  Driver d(s);
  // Rising at 12 deg/s from -30 deg for 2 s, then stopped at -6 deg for 3 s, then rising again.
  auto angle = [](double t) {
    if (t < 2.0) return (-30.0 + 12.0 * t) * kDeg;
    if (t < 5.0) return -6.0 * kDeg;
    return (-6.0 + 12.0 * (t - 5.0)) * kDeg;
  };
  for (int k = 0; k <= 6 * 40; ++k) d.add(k / 40.0, angle(k / 40.0));
  // 0.3 deg per line: the last move by more than the hysteresis (1 deg) is at most 4 lines
  // before the stop (line 80); stalled 1 s (40 lines) after it, the sweep is closed there.
  ASSERT_GE(d.sweeps.size(), 1u);
  EXPECT_EQ(d.sweep_reasons[0], CutReason::Stall);
  const int stall_line = d.sweeps[0].back();
  EXPECT_GE(stall_line, 2 * 40 + 40 - 4);  // 1 s after the tilt reached (almost) -6 deg
  EXPECT_LE(stall_line, 2 * 40 + 40);
  EXPECT_EQ(d.sweeps[0].front(), 0);
  // Every line until the tilt has moved on by more than 1 deg is discarded as Stalled; the
  // first that has starts the next sweep.
  ASSERT_FALSE(d.discarded.empty());
  EXPECT_EQ(d.discarded.front(), stall_line + 1);
  for (CutReason r : d.discard_reasons) EXPECT_EQ(r, CutReason::Stalled);
  const int resumed = d.discarded.back() + 1;
  EXPECT_GT(angle(resumed / 40.0), -5.0 * kDeg);          // moved by more than 1 deg
  EXPECT_LE(angle((resumed - 1) / 40.0), -5.0 * kDeg);    // the one before had not
  EXPECT_EQ(int(d.discarded.size()), resumed - stall_line - 1);
  EXPECT_FALSE(d.cutter.stalled());
  EXPECT_EQ(d.cutter.pendingLines(), std::size_t(6 * 40 - resumed + 1));
  // A dwell shorter than stall_timeout at a turning point is no stall.
  Driver dwell(s);
  auto dwell_angle = [](double t) {
    if (t < 2.0) return (-30.0 + 12.0 * t) * kDeg;
    if (t < 2.8) return -6.0 * kDeg;
    return (-6.0 - 12.0 * (t - 2.8)) * kDeg;
  };
  for (int k = 0; k <= 4 * 40; ++k) dwell.add(k / 40.0, dwell_angle(k / 40.0));
  ASSERT_EQ(dwell.sweeps.size(), 1u);
  EXPECT_EQ(dwell.sweep_reasons[0], CutReason::TurningPoint);
  EXPECT_EQ(dwell.sweeps[0].back(), 80);  // the first line at the extreme
  EXPECT_TRUE(dwell.discarded.empty());
}

TEST(SweepCutter, AGapClosesTheSweepAndTooFewLinesAreDiscarded) {
  SweepCutterSettings s;
  s.min_lines = 10;
  Driver d(s);
  for (int k = 0; k < 30; ++k) d.add(k * 0.025, std::nullopt);
  // A 0.6 s gap (> 0.5): the 30 lines are a sweep; the line after the gap starts the next.
  CutResult r = d.add(29 * 0.025 + 0.6, std::nullopt);
  EXPECT_EQ(r.event, CutEvent::SweepEnded);
  EXPECT_EQ(r.reason, CutReason::Gap);
  ASSERT_EQ(d.sweeps.size(), 1u);
  EXPECT_EQ(d.sweeps[0].size(), 30u);
  EXPECT_EQ(d.cutter.pendingLines(), 1u);
  // Gaps just below max_line_gap do not cut.
  const double t1 = 29 * 0.025 + 0.6;
  for (int k = 1; k < 5; ++k) d.add(t1 + 0.49 * k, std::nullopt);
  EXPECT_EQ(d.sweeps.size(), 1u);
  // Now 5 lines; another gap: fewer than min_lines, discarded with the reason.
  r = d.add(t1 + 2.0 + 3.0, std::nullopt);
  EXPECT_EQ(r.event, CutEvent::Discarded);
  EXPECT_EQ(r.reason, CutReason::Gap);
  EXPECT_EQ(r.closed_lines, 5u);
  EXPECT_TRUE(r.line_kept);
  EXPECT_EQ(d.discarded.size(), 5u);
  EXPECT_EQ(d.sweeps.size(), 1u);
}

TEST(SweepCutter, TooFewLinesBeforeATurningPointAreDiscarded) {
  SweepCutterSettings s;
  s.min_lines = 10;
  Driver d(s);
  // Rising for 5 lines (1 deg per line), then falling: the 5-line "sweep" is discarded.
  for (int k = 0; k < 5; ++k) d.add(k * 0.025, k * kDeg);
  for (int k = 5; k < 40; ++k) d.add(k * 0.025, (8 - k) * kDeg);
  EXPECT_TRUE(d.sweeps.empty());
  ASSERT_EQ(d.discarded.size(), 5u);  // lines 0..4 (line 4 at the extreme)
  EXPECT_EQ(d.discarded.back(), 4);
  EXPECT_EQ(d.discard_reasons.back(), CutReason::TurningPoint);
  EXPECT_EQ(d.cutter.pendingLines(), 35u);
}

TEST(SweepCutter, TimeGoingBackwardsResetsAndLateLinesAreDropped) {
  SweepCutterSettings s;
  Driver d(s);
  for (int k = 0; k < 100; ++k) d.add(500.0 + k / 40.0, triangle(k / 40.0, 30 * kDeg, 4.5));
  // A late line (0.1 s older than the newest): dropped, nothing else changes.
  CutResult r = d.add(500.0 + 99 / 40.0 - 0.1, 0.0);
  EXPECT_EQ(r.event, CutEvent::Discarded);
  EXPECT_EQ(r.reason, CutReason::LateLine);
  EXPECT_FALSE(r.line_kept);
  EXPECT_EQ(r.closed_lines, 0u);
  EXPECT_EQ(d.cutter.pendingLines(), 100u);
  // A line at the same stamp as the newest is not late.
  EXPECT_EQ(d.add(500.0 + 99 / 40.0, triangle(99 / 40.0, 30 * kDeg, 4.5)).event, CutEvent::Continue);
  // The bag loops: back to t = 10 s. The 101 lines are closed (a sweep: >= min_lines) and
  // the cutter starts afresh with this line.
  r = d.add(10.0, triangle(0.0, 30 * kDeg, 4.5));
  EXPECT_EQ(r.event, CutEvent::SweepEnded);
  EXPECT_EQ(r.reason, CutReason::TimeBackwards);
  EXPECT_EQ(r.closed_lines, 101u);
  EXPECT_EQ(d.cutter.pendingLines(), 1u);
  // Afresh: the turning point at 4.5 s after the restart is cut where it should be.
  for (int k = 1; k <= 200; ++k) d.add(10.0 + k / 40.0, triangle(k / 40.0, 30 * kDeg, 4.5));
  ASSERT_EQ(d.sweeps.size(), 2u);
  EXPECT_EQ(d.sweep_reasons[1], CutReason::TurningPoint);
  EXPECT_EQ(d.sweeps[1].size(), 181u);  // the restart line (at -30 deg) to the one at +30 deg
  // A single pending line is closed as a sweep when min_lines is 1.
  SweepCutterSettings one = s;
  one.min_lines = 1;
  SweepCutter c(one);
  c.addLine(100.0, std::nullopt);
  r = c.addLine(50.0, std::nullopt);
  EXPECT_EQ(r.event, CutEvent::SweepEnded);
  EXPECT_EQ(r.reason, CutReason::TimeBackwards);
  EXPECT_EQ(r.closed_lines, 1u);
}

TEST(SweepCutter, MaxLinesBoundsASweepThatNeverTurns) {
  SweepCutterSettings s;
  s.max_lines = 50;
  Driver d(s);
  // A slow, steady tilt (0.05 deg per line: never stalls within 1 s, never turns).
  for (int k = 0; k < 120; ++k) d.add(k / 40.0, (0.05 * k) * kDeg);
  ASSERT_EQ(d.sweeps.size(), 2u);
  EXPECT_EQ(d.sweep_reasons[0], CutReason::MaxLines);
  EXPECT_EQ(d.sweeps[0].size(), 50u);
  EXPECT_EQ(d.sweeps[1].front(), 50);
  EXPECT_EQ(d.cutter.pendingLines(), 20u);
}

TEST(SweepCutter, UnwrapsAnglesAcrossPlusMinusPi) {
  // A tilt rising through 180 deg (atan2 jumps from +pi to -pi): no turning point.
  SweepCutterSettings s;
  Driver d(s);
  for (int k = 0; k < 200; ++k) {
    d.add(k / 40.0, std::remainder((150.0 + 0.5 * k) * kDeg, 2.0 * M_PI));
  }
  EXPECT_TRUE(d.sweeps.empty());
  EXPECT_TRUE(d.discarded.empty());
}

TEST(SweepCutter, InvalidSettingsAreRefusedByName) {
  auto message = [](SweepCutterSettings s) {
    try {
      SweepCutter c(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  SweepCutterSettings s;
  s.turn_hysteresis = -0.1;
  EXPECT_NE(message(s).find("turn_hysteresis"), std::string::npos);
  s = SweepCutterSettings{};
  s.sweep_duration = NAN;
  EXPECT_NE(message(s).find("sweep_duration"), std::string::npos);
  s = SweepCutterSettings{};
  s.stall_timeout = -1;
  EXPECT_NE(message(s).find("stall_timeout"), std::string::npos);
  s = SweepCutterSettings{};
  s.max_line_gap = 0.0;
  EXPECT_NE(message(s).find("max_line_gap"), std::string::npos);
  s = SweepCutterSettings{};
  s.min_lines = 0;
  EXPECT_NE(message(s).find("min_lines"), std::string::npos);
  s = SweepCutterSettings{};
  s.max_lines = s.min_lines - 1;
  EXPECT_NE(message(s).find("max_lines"), std::string::npos);
  EXPECT_EQ(message(SweepCutterSettings{}), "");
  SweepCutter c;
  EXPECT_THROW(c.addLine(NAN, 0.0), std::invalid_argument);
}
