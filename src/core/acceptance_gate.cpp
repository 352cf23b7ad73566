#include "cube_scan_matcher/core/acceptance_gate.h"

#include <cmath>
#include <stdexcept>

#include "cube_scan_matcher/core/pose_covariance.h"

namespace cube_scan_matcher {

std::string toString(GateReason reason) {
  switch (reason) {
    case GateReason::Accepted: return "accepted";
    case GateReason::FirstScan: return "first_scan";
    case GateReason::LowOverlap: return "low_overlap";
    case GateReason::NoGain: return "no_gain";
    case GateReason::CorrectionTooLarge: return "correction_too_large";
    case GateReason::RegistrationFailed: return "registration_failed";
    case GateReason::BadReference: return "bad_reference";
    case GateReason::SkippedNoTf: return "skipped_no_tf";
    case GateReason::BadInput: return "bad_input";
    case GateReason::Unconfirmed: return "unconfirmed";
    case GateReason::Degenerate: return "degenerate";
    case GateReason::Uncertain: return "uncertain";
    case GateReason::Ambiguous: return "ambiguous";
    case GateReason::NonFinite: return "non_finite";
    case GateReason::BentSweep: return "bent_sweep";
  }
  return "unknown";
}

void validate(const GateSettings& s) {
  if (!(s.min_overlap >= 0.0 && s.min_overlap <= 1.0))
    throw std::invalid_argument("min_overlap must be in [0, 1], got " + std::to_string(s.min_overlap));
  if (!(s.max_correction_m > 0.0 && std::isfinite(s.max_correction_m)))
    throw std::invalid_argument("max_correction_translation must be > 0 m");
  if (!(s.max_correction_rad > 0.0 && std::isfinite(s.max_correction_rad)))
    throw std::invalid_argument("max_correction_rotation must be > 0");
  if (!(s.max_sigma_m >= 0.0 && std::isfinite(s.max_sigma_m)))
    throw std::invalid_argument("max_sigma_translation must be >= 0 m (0 = off)");
}

Pose6 correctionFromGuess(const Pose6& guess, const Pose6& result) {
  return isometryToPose(poseToIsometry(guess).inverse() * poseToIsometry(result));
}

GateReason gate(const RegistrationResult& r, const Pose6& guess, const GateSettings& s) {
  if (!r.ok()) return GateReason::RegistrationFailed;
  if (r.overlap() < s.min_overlap) return GateReason::LowOverlap;
  // The gain of the search on the objective it maximised against the guess: the coarse stage's
  // best J (eq. 5 on the E grid). J at the refined pose can be a few cubes below J at an exact
  // guess (the refine optimises the finer grids), which is no sign of a bad result.
  if (r.J_coarse < r.J_guess) return GateReason::NoGain;
  const Eigen::Isometry3d c = poseToIsometry(guess).inverse() * r.transform;
  if (c.translation().norm() > s.max_correction_m ||
      Eigen::AngleAxisd(c.linear()).angle() > s.max_correction_rad) {
    return GateReason::CorrectionTooLarge;
  }
  if (s.require_polish && r.polish_tried && !r.polished) return GateReason::Unconfirmed;
  if (s.reject_ambiguous && r.ambiguous) return GateReason::Ambiguous;
  if (s.reject_degenerate && r.polished && r.degenerate) return GateReason::Degenerate;
  if (s.max_sigma_m > 0.0 && r.polished && largestTranslationSigma(r.covariance) > s.max_sigma_m) {
    return GateReason::Uncertain;
  }
  return GateReason::Accepted;
}

}  // namespace cube_scan_matcher
