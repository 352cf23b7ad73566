// Acceptance gate of an online registration: decides whether a result may replace the
// odometry increment. ROS-free; the nodelet publishes its reason codes in Status.msg.
#pragma once

#include <cstdint>
#include <string>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// Why a scan was (not) used. The values are those of Status.msg's reason field.
enum class GateReason : std::uint8_t {
  Accepted = 0,            ///< registration used.
  FirstScan = 1,           ///< no previous scan: the scan becomes the reference.
  LowOverlap = 2,          ///< J / l below min_overlap.
  NoGain = 3,              ///< coarse-stage J below J at the guess.
  CorrectionTooLarge = 4,  ///< result too far from the guess.
  RegistrationFailed = 5,  ///< the core returned no result (no overlap, empty scan).
  BadReference = 6,        ///< this scan's cube grid could not be built (e.g. memory cap).
  SkippedNoTf = 7,         ///< odometry tf missing and missing_tf_policy = skip.
  BadInput = 8,            ///< no usable point (empty, all NaN, no x/y/z fields).
  Unconfirmed = 9,  ///< the point-to-plane polish did not confirm the cube result.
  Degenerate = 10,  ///< a direction of the result has (almost) no information.
  Uncertain = 11,   ///< the result's covariance is too wide.
  Ambiguous = 12,   ///< weakly fixed, the starts disagree, and no retry landed on it again.
  /// The step would put a NaN, infinite or non-rigid pose into the chain: refused, the chain
  /// keeps its last known pose (OnlineMatcher::process).
  NonFinite = 13,
  /// A sweep after rejected scans whose de-skewed registration fits the reference's planes
  /// much worse than the recent accepted results (a higher plane RMS or fewer points on
  /// planes): still bent by a motion nothing registered (DeskewSettings::max_rms_ratio,
  /// min_plane_fraction_ratio).
  BentSweep = 14,
};
std::string toString(GateReason reason);

struct GateSettings {
  double min_overlap = 0.10;           ///< minimum J / l, in [0, 1].
  double max_correction_m = 2.0;       ///< |translation of guess^-1 * result| [m], > 0.
  double max_correction_rad = 0.2617993877991494;  ///< rotation angle of the same [rad], > 0.
  /// Reject a result the polish ran on but did not apply: it moved more than its max_shift from
  /// the cube result or found too few planes, i.e. the cube result is not at a minimum of the
  /// point-to-plane distances (scene benchmark: 4 of 11 wrong results, 1 of 1588 right ones).
  bool require_polish = true;
  /// Reject a result flagged degenerate (RegistrationResult::degenerate: its weakest direction
  /// has less than polish.degenerate_ratio of the strongest's information). The search can
  /// slide along such a direction; the odometry then carries the increment (scene benchmark:
  /// 5 of 11 wrong results, 2 of 1588 right ones; in a corridor every scan is rejected).
  bool reject_degenerate = true;
  /// Reject a result marked ambiguous (RegistrationResult::ambiguous, SearchSettings::
  /// ambiguous_weak_ratio): weakly fixed along a translation axis, most starts found other
  /// maxima, and no retry landed on the same pose (robot worlds with the sensor's artefacts at
  /// collapse 0.5: it takes the wrongly accepted results from 7 to 3; docs/experiments.md,
  /// "The axis probe, the consensus rule and the coarse collapse E/2").
  bool reject_ambiguous = true;
  /// Reject a polished result whose largest translation standard deviation (from its
  /// covariance, RegistrationResult::covariance, calibrated on the scene benchmark) exceeds
  /// this [m]; 0 = off. A sanity bound, not a separator: on the scene benchmark no wrong
  /// result has been rejected by it alone. With the clustered covariance (PolishSettings::
  /// covariance_cell_m) and the jackknife, right results in the robot worlds reach about 9 cm:
  /// 5 cm rejects 13 of their 2400 as uncertain, and 65 accepted right ones lie above 3 cm
  /// (trial seed 2, docs/results/scenes/scenes_robot.csv). >= 0.
  double max_sigma_m = 0.05;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const GateSettings& settings);

/// Correction of the result relative to the guess, guess^-1 * result, as [x y z roll pitch yaw].
Pose6 correctionFromGuess(const Pose6& guess, const Pose6& result);

/// Applies the gate to a result of CubeRegistration::align around `guess`.
GateReason gate(const RegistrationResult& result, const Pose6& guess, const GateSettings& s);

}  // namespace cube_scan_matcher
