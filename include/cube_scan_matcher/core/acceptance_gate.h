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
  NoGain = 3,              ///< coarse-stage J below J at the guess + min_j_gain.
  CorrectionTooLarge = 4,  ///< result too far from the guess.
  RegistrationFailed = 5,  ///< the core returned no result (no overlap, empty scan).
  BadReference = 6,        ///< this scan's cube grid could not be built (e.g. memory cap).
  SkippedNoTf = 7,         ///< odometry tf missing and missing_tf_policy = skip.
  BadInput = 8,            ///< no usable point (empty, all NaN, no x/y/z fields).
};
std::string toString(GateReason reason);

struct GateSettings {
  double min_overlap = 0.10;           ///< minimum J / l, in [0, 1].
  int min_j_gain = 0;  ///< the coarse stage's J must be >= J at the guess + this, >= 0.
  double max_correction_m = 2.0;       ///< |translation of guess^-1 * result| [m], > 0.
  double max_correction_rad = 0.2617993877991494;  ///< rotation angle of the same [rad], > 0.
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const GateSettings& settings);

/// Correction of the result relative to the guess, guess^-1 * result, as [x y z roll pitch yaw].
Pose6 correctionFromGuess(const Pose6& guess, const Pose6& result);

/// Applies the gate to a result of CubeRegistration::align around `guess`.
GateReason gate(const RegistrationResult& result, const Pose6& guess, const GateSettings& s);

}  // namespace cube_scan_matcher
