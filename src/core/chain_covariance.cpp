#include "cube_scan_matcher/core/chain_covariance.h"

#include <cmath>
#include <stdexcept>

#include "cube_scan_matcher/core/vector6.h"

namespace cube_scan_matcher {

void validate(const ChainCovarianceSettings& s) {
  if (!(s.sigma_m > 0.0) || !std::isfinite(s.sigma_m)) {
    throw std::invalid_argument("chain covariance: sigma_m must be finite and > 0 [m]");
  }
  if (!(s.sigma_rad > 0.0) || !std::isfinite(s.sigma_rad)) {
    throw std::invalid_argument("chain covariance: sigma_rad must be finite and > 0 [rad]");
  }
  if (!(s.rejected_sigma_m > 0.0) || !std::isfinite(s.rejected_sigma_m) ||
      !(s.rejected_sigma_rad > 0.0) || !std::isfinite(s.rejected_sigma_rad)) {
    throw std::invalid_argument("chain covariance: rejected sigmas must be finite and > 0");
  }
  if (!(s.registration_scale > 0.0) || !(s.registration_scale <= 1.0)) {
    throw std::invalid_argument("chain covariance: registration_scale must be in (0, 1]");
  }
  if (!(s.drift_fraction >= 0.0) || !std::isfinite(s.drift_fraction)) {
    throw std::invalid_argument("chain covariance: drift_fraction must be finite and >= 0");
  }
}

ChainCovariance::ChainCovariance(const ChainCovarianceSettings& settings) : settings_(settings) {
  validate(settings_);
}

void ChainCovariance::setSettings(const ChainCovarianceSettings& settings) {
  validate(settings);
  settings_ = settings;
}

void ChainCovariance::restart(const std::optional<Matrix6d>& start) { start_ = start; }

StepCovariance ChainCovariance::add(const OnlineStep& step) {
  const double st = settings_.sigma_m, sr = settings_.sigma_rad;
  const Eigen::Isometry3d keyframe = step.pose * step.increment.inverse();  // T_map_keyframe
  const Eigen::Vector3d lever_arm = step.pose.translation() - keyframe.translation();
  // The systematic part's covariance for a displacement [m].
  auto drift = [this](const Eigen::Vector3d& displacement) {
    Matrix6d c = Matrix6d::Zero();
    const double f = settings_.drift_fraction;
    c.topLeftCorner<3, 3>() = f * f * displacement * displacement.transpose();
    return c;
  };
  StepCovariance out;
  Matrix6d random, increment_map;
  // A first scan that could not become the reference (BadReference) starts the chain too, and
  // the next scan, again a first one, starts it over with the same start covariance.
  const bool chain_start =
      step.reason == GateReason::FirstScan || step.reason == GateReason::BadReference;
  if (chain_start) {
    out.increment = diagonalCovariance(st, sr);
    random = start_ ? *start_ : out.increment;
    out.motion = out.increment;
    increment_map = Matrix6d::Zero();
    start_position_ = step.pose.translation();
    if (step.reason == GateReason::FirstScan) start_.reset();
  } else {
    const double scale = settings_.registration_scale;
    out.increment = step.accepted ? floorCovariance(scale * scale * step.result.covariance, st, sr)
                                  : diagonalCovariance(settings_.rejected_sigma_m,
                                                       settings_.rejected_sigma_rad);
    increment_map = rotateCovariance(out.increment, keyframe.linear());
    random = compoundCovariance(keyframe_, increment_map, lever_arm);
    const Eigen::Vector3d moved = step.pose.translation() - last_position_;
    out.motion = increment_map + last_increment_ + drift(moved);
  }
  last_position_ = step.pose.translation();
  last_increment_ = step.reference_updated ? Matrix6d::Zero() : increment_map;
  if (step.reference_updated) keyframe_ = random;
  out.pose = random + drift(step.pose.translation() - start_position_);
  return out;
}

}  // namespace cube_scan_matcher
