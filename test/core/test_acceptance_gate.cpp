// The acceptance gate: low overlap, no gain, large corrections, unconfirmed and degenerate
// results are rejected with reasons.
#include <gtest/gtest.h>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

TEST(AcceptanceGate, RejectsLowOverlapNoGainAndLargeCorrections) {
  RegistrationResult r;
  r.status = RegistrationStatus::Ok;
  r.reference_cubes = 1000;
  r.J = r.J_coarse = 500;
  r.J_guess = 400;
  r.pose << 0.2, 0, 0, 0, 0, 0;
  r.transform = poseToIsometry(r.pose);
  const Pose6 guess = Pose6::Zero();
  GateSettings g;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  g.min_overlap = 0.6;
  EXPECT_EQ(gate(r, guess, g), GateReason::LowOverlap);
  g = GateSettings{};
  r.J_guess = 501;  // the search ended below its own start
  EXPECT_EQ(gate(r, guess, g), GateReason::NoGain);
  r.J_guess = 400;
  g.max_correction_m = 0.1;
  EXPECT_EQ(gate(r, guess, g), GateReason::CorrectionTooLarge);
  r.status = RegistrationStatus::NoOverlap;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::RegistrationFailed);
  g = GateSettings{};
  g.min_overlap = 1.5;
  EXPECT_THROW(validate(g), std::invalid_argument);
}

// An exact guess: the refined pose can score a few E-grid cubes below it (the refine maximises
// the finer grids). The gain is judged on the coarse stage's best J, not on J at the result.
TEST(AcceptanceGate, NoGainIsJudgedOnTheCoarseStage) {
  RegistrationResult r;
  r.status = RegistrationStatus::Ok;
  r.reference_cubes = 1000;
  r.J_guess = 600;
  r.J_coarse = 601;
  r.J = 599;
  const Pose6 guess = Pose6::Zero();
  r.pose = guess;
  r.transform = poseToIsometry(r.pose);
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Accepted);
  r.J_coarse = 599;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::NoGain);
}

namespace {
/// A result the first checks accept: overlap 0.5, J 100 above J at the guess, no correction.
RegistrationResult gainingResult() {
  RegistrationResult r;
  r.status = RegistrationStatus::Ok;
  r.reference_cubes = 1000;
  r.J = r.J_coarse = 500;
  r.J_guess = 400;
  r.transform = poseToIsometry(r.pose);
  return r;
}
}  // namespace

// A result the polish ran on but did not apply is unconfirmed; a polished result flagged
// degenerate is rejected; each only while its switch is on, and a result without the polish
// (the paper's mode) is judged without them.
TEST(AcceptanceGate, RejectsUnconfirmedAndDegenerateResults) {
  RegistrationResult r = gainingResult();
  const Pose6 guess = Pose6::Zero();
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Accepted);  // no polish ran
  r.polish_tried = true;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Unconfirmed);
  GateSettings g;
  g.require_polish = false;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  r.polished = true;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Accepted);
  r.degenerate = true;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Degenerate);
  g = GateSettings{};
  g.reject_degenerate = false;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  EXPECT_EQ(toString(GateReason::Unconfirmed), "unconfirmed");
  EXPECT_EQ(toString(GateReason::Degenerate), "degenerate");
}

// A result marked ambiguous (no retry landed on it again) is rejected unless reject_ambiguous
// is off; one confirmed by a consensus is not.
TEST(AcceptanceGate, RejectsAnAmbiguousResult) {
  RegistrationResult r = gainingResult();
  r.polish_tried = r.polished = true;
  const Pose6 guess = Pose6::Zero();
  r.consensus = true;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Accepted);
  r.consensus = false;
  r.ambiguous = true;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Ambiguous);
  GateSettings g;
  g.reject_ambiguous = false;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  EXPECT_EQ(toString(GateReason::Ambiguous), "ambiguous");
  EXPECT_EQ(toString(GateReason::BentSweep), "bent_sweep");
}

// A polished result whose translation standard deviation (along any direction) exceeds
// max_sigma_m is uncertain; 0 turns the check off.
TEST(AcceptanceGate, RejectsResultsWithAWideCovariance) {
  RegistrationResult r = gainingResult();
  r.polish_tried = r.polished = true;
  r.covariance.diagonal() << 1e-6, 1e-6, 1e-6, 1e-8, 1e-8, 1e-8;  // 1 mm
  const Pose6 guess = Pose6::Zero();
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Accepted);
  // 6.9 cm along the diagonal of x and y: each of x and y alone has 4.9 cm, below the
  // default 5.
  r.covariance(0, 0) = r.covariance(1, 1) = 2.4e-3;
  r.covariance(0, 1) = r.covariance(1, 0) = 2.4e-3 - 1e-6;
  EXPECT_EQ(gate(r, guess, GateSettings{}), GateReason::Uncertain);
  GateSettings g;
  g.max_sigma_m = 0.0;
  EXPECT_EQ(gate(r, guess, g), GateReason::Accepted);
  g.max_sigma_m = -1.0;
  EXPECT_THROW(validate(g), std::invalid_argument);
  EXPECT_EQ(toString(GateReason::Uncertain), "uncertain");
}
