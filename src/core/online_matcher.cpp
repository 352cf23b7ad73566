#include "cube_scan_matcher/core/online_matcher.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace cube_scan_matcher {

void validate(const OnlineMatcherSettings& s) {
  validate(s.registration);
  validate(s.gate);
  if (s.max_consecutive_rejections < 1) {
    throw std::invalid_argument("max_consecutive_rejections must be >= 1, got " +
                                std::to_string(s.max_consecutive_rejections));
  }
}

OnlineMatcher::OnlineMatcher(const OnlineMatcherSettings& settings)
    : settings_(settings), registration_(settings.registration) {}

void OnlineMatcher::reset() {
  registration_ = CubeRegistration(settings_.registration);
  reference_points_ = PointArray{};
  reference_pose_ = last_pose_ = Eigen::Isometry3d::Identity();
  anchor_.reset();
  reference_is_anchor_ = false;
  last_stamp_.reset();
  intervals_.clear();
  consecutive_rejections_ = 0;
  start_pose_.reset();
}

void OnlineMatcher::restartAt(const Eigen::Isometry3d& pose) {
  reset();
  start_pose_ = pose;
}

void OnlineMatcher::setSettings(const OnlineMatcherSettings& settings) {
  validate(settings);
  if (registration_.hasReference()) {
    // Build the reference's grids with the new settings first: settings whose grids cannot be
    // built (the memory cap) throw here and leave the matcher as it was.
    CubeRegistration rebuilt(settings.registration);
    try {
      rebuilt.setReference(reference_points_);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("the current reference cannot be built with these "
                                              "settings: ") + e.what());
    }
    registration_ = std::move(rebuilt);
  } else {
    registration_.setSettings(settings.registration);
  }
  settings_ = settings;
}

double OnlineMatcher::gateScale(double stamp) const {
  if (intervals_.empty()) return 1.0;
  // The scan period: the lower quartile of the recent intervals (the matcher sees longer ones
  // whenever scans are dropped; a few odd short ones do not move the quartile).
  std::vector<double> v(intervals_.begin(), intervals_.end());
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 4), v.end());
  const double period = v[v.size() / 4];
  // Whole periods: timing jitter does not widen the bounds, a missed scan does.
  return std::clamp(std::round((stamp - reference_stamp_) / period), 1.0, kMaxGateScale);
}

OnlineStep OnlineMatcher::process(const PointArray& points, double stamp,
                                  const std::optional<Eigen::Isometry3d>& odom) {
  OnlineStep step;
  if (last_stamp_ && stamp < *last_stamp_) {
    // The scan period is the sensor's: it survives a bag loop or a clock reset.
    std::deque<double> intervals = std::move(intervals_);
    reset();
    intervals_ = std::move(intervals);
    step.time_reset = true;
  }
  if (last_stamp_ && stamp > *last_stamp_) {
    intervals_.push_back(stamp - *last_stamp_);
    if (intervals_.size() > kIntervals) intervals_.pop_front();
  }
  last_stamp_ = stamp;
  const bool first = !registration_.hasReference();
  step.odometry_guess = odom && anchor_;
  Eigen::Isometry3d odom_increment = Eigen::Isometry3d::Identity();
  if (step.odometry_guess) {
    odom_increment = anchor_->odom.inverse() * *odom;
    // Over references without odometry: predicted map pose, seen from the reference.
    if (!reference_is_anchor_) odom_increment = reference_pose_.inverse() * anchor_->pose * odom_increment;
  }
  step.guess = isometryToPose(odom_increment);
  step.increment = odom_increment;

  if (first) {
    step.reason = points.empty() ? GateReason::BadInput : GateReason::FirstScan;
    step.pose = start_pose_ ? *start_pose_ : odom ? *odom : Eigen::Isometry3d::Identity();
  } else if (points.empty()) {
    step.reason = GateReason::BadInput;
  } else {
    step.registered = true;
    step.gate_scale = gateScale(stamp);
    if (step.gate_scale > 1.0) {
      // The guess spans several increments: search as much wider as the gate is.
      RegistrationSettings wide = settings_.registration;
      wide.gnmm.bounds *= step.gate_scale;
      registration_.setSettings(wide);
      step.result = registration_.align(points, step.guess);
      registration_.setSettings(settings_.registration);
    } else {
      step.result = registration_.align(points, step.guess);
    }
    GateSettings gate_settings = settings_.gate;
    gate_settings.max_correction_m *= step.gate_scale;
    gate_settings.max_correction_rad *= step.gate_scale;
    step.reason = gate(step.result, step.guess, gate_settings);
    if (step.result.ok()) step.correction = correctionFromGuess(step.guess, step.result.pose);
    step.accepted = step.reason == GateReason::Accepted;
    if (step.accepted) step.increment = step.result.transform;
  }
  if (!first) {
    step.pose = reference_pose_ * step.increment;
    step.interval = stamp - reference_stamp_;
  }

  const bool rejected = !first && !step.accepted;
  consecutive_rejections_ = rejected ? consecutive_rejections_ + 1 : 0;
  step.consecutive_rejections = consecutive_rejections_;
  step.rejection_alarm = consecutive_rejections_ >= settings_.max_consecutive_rejections;

  // This scan becomes the reference if it has points, its pose is known (or the chain has to
  // move on) and its grid can be built.
  const bool pose_unknown = rejected && !odom && !step.rejection_alarm;
  if (pose_unknown && !points.empty()) {
    if (!step.message.empty()) step.message += "; ";
    step.message += "scan not used as reference: no odometry and the registration rejected";
  } else if (!points.empty()) {
    try {
      registration_.setReference(points);
      reference_points_ = points;
      reference_pose_ = step.pose;
      reference_stamp_ = stamp;
      reference_is_anchor_ = odom.has_value();
      if (odom) anchor_ = OdometryAnchor{step.pose, *odom};
      step.reference_updated = true;
      if (first) start_pose_.reset();
    } catch (const std::exception& e) {
      if (first) step.reason = GateReason::BadReference;
      if (!step.message.empty()) step.message += "; ";
      step.message += std::string("scan not used as reference: ") + e.what();
    }
  }
  last_pose_ = step.pose;

  std::ostringstream os;
  os << toString(step.reason);
  if (step.registered) os << " (" << step.result.message << ")";
  if (step.gate_scale > 1.0) os << "; correction bounds x" << step.gate_scale << " (scans missed)";
  if (!step.message.empty()) os << "; " << step.message;
  step.message = os.str();
  return step;
}

}  // namespace cube_scan_matcher
