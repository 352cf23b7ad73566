#include "cube_scan_matcher/core/online_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/core/deskew.h"
#include "require_in_range.h"
#include "reuse_memory.h"

namespace cube_scan_matcher {

namespace {

/// Wall time [s] since `start`.
double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// One align() call's work, added to the step's.
void countAlign(OnlineWork& work, const RegistrationResult& r) {
  ++work.aligns;
  work.searches += r.attempts;
  work.evaluations += r.evaluations;
  work.coarse_s += r.time_coarse_s;
  work.refine_s += r.time_refine_s;
  work.polish_s += r.time_polish_s;
}

/// The correction from `guess` to `result` in units of the gate's correction bounds: the larger
/// of its translation over max_correction_m and its rotation angle over max_correction_rad.
double correctionSize(const Pose6& guess, const Pose6& result, const GateSettings& gate) {
  const Eigen::Isometry3d c = poseToIsometry(guess).inverse() * poseToIsometry(result);
  return std::max(c.translation().norm() / gate.max_correction_m,
                  Eigen::AngleAxisd(c.linear()).angle() / gate.max_correction_rad);
}

}  // namespace

void validate(const OnlineMatcherSettings& s) {
  validate(s.registration);
  validate(s.gate);
  if (s.max_consecutive_rejections < 1) {
    throw std::invalid_argument("max_consecutive_rejections must be >= 1, got " +
                                std::to_string(s.max_consecutive_rejections));
  }
  const KeyframeSettings& k = s.keyframes;
  requireInRange("keyframe distance [m]", k.distance, 0.0, 1000.0);
  requireInRange("keyframe angle [rad]", k.angle, 0.0, double(EIGEN_PI));
  requireInRange("keyframe interval [s]", k.interval, 0.0, 1e6);
  requireInRange("submap size [keyframes]", k.submap_size, 1, 20);
  requireInRange("no_odometry_scale", s.no_odometry_scale, 1.0, 10.0);
  requireInRange("no_motion_dense_points", s.no_motion_dense_points, 0, 1000);
  requireInRange("no_odometry_dense_points", s.no_odometry_dense_points, 0, 1000);
  // The grid as wide as the rejections can make it (registerAndGate) must be valid too.
  PlanarGridSettings widest = s.no_odometry_grid;
  widest.half_yaw = widest.half_yaw > 0.0 ? double(EIGEN_PI) : 0.0;
  validate(widest);
  requireInRange("deskew iterations", s.deskew.iterations, 0, 10);
  if (s.deskew.max_rms_ratio != 0.0) {
    requireInRange("deskew max_rms_ratio", s.deskew.max_rms_ratio, 1.0, 100.0);
  }
  requireInRange("deskew min_plane_fraction_ratio", s.deskew.min_plane_fraction_ratio, 0.0, 1.0);
}

OnlineMatcher::OnlineMatcher(const OnlineMatcherSettings& settings)
    : settings_(settings), registration_(settings.registration) {
  validate(settings);
}

void OnlineMatcher::reset() {
  registration_ = CubeRegistration(settings_.registration);
  keyframes_.clear();
  last_pose_ = Eigen::Isometry3d::Identity();
  last_known_.reset();
  previous_odom_.reset();
  velocity_ = Pose6::Zero();
  anchor_.reset();
  last_stamp_.reset();
  intervals_.clear();
  recent_fits_.clear();
  consecutive_rejections_ = 0;
  start_pose_.reset();
}

std::size_t OnlineMatcher::keyframeBytes() const {
  std::size_t bytes = 0;
  for (const Keyframe& k : keyframes_) bytes += 3 * k.points.x.capacity() * sizeof(float);
  return bytes;
}

void OnlineMatcher::restartAt(const Eigen::Isometry3d& pose) {
  if (!isRigid(pose)) throw std::invalid_argument("restartAt: the pose is not a finite rigid motion");
  reset();
  start_pose_ = pose;
}

void OnlineMatcher::submapPoints(const std::deque<Keyframe>& keyframes, int submap_size,
                                 PointArray& out) {
  const std::size_t n = std::min(keyframes.size(), std::size_t(submap_size));
  std::size_t total = 0;
  for (std::size_t i = keyframes.size() - n; i < keyframes.size(); ++i) {
    total += keyframes[i].points.size();
  }
  clearForRebuild(out, total);
  if (n == 1) {
    const PointArray& only = keyframes.back().points;
    out.x = only.x, out.y = only.y, out.z = only.z;  // within the reserved capacity
    return;
  }
  const Eigen::Isometry3d to_newest = keyframes.back().pose.inverse();
  for (std::size_t i = keyframes.size() - n; i < keyframes.size(); ++i) {
    appendTransformed(out, keyframes[i].points, to_newest * keyframes[i].pose);
  }
}

bool OnlineMatcher::addKeyframe(const PointArray& points, const Eigen::Isometry3d& pose,
                                double stamp, std::string& why) {
  // The keyframe's copy of the points goes into the memory of the last keyframe to leave.
  PointArray copy = std::move(recycled_);
  clearForRebuild(copy, points.size());
  copy.x = points.x, copy.y = points.y, copy.z = points.z;
  keyframes_.push_back(Keyframe{std::move(copy), pose, stamp});
  try {
    submapPoints(keyframes_, settings_.keyframes.submap_size, submap_);
    registration_.setReference(submap_);
  } catch (const std::exception& e) {
    recycled_ = std::move(keyframes_.back().points);
    keyframes_.pop_back();
    why = e.what();
    return false;
  }
  while (keyframes_.size() > std::size_t(settings_.keyframes.submap_size)) {
    recycled_ = std::move(keyframes_.front().points);
    keyframes_.pop_front();
  }
  return true;
}

void OnlineMatcher::setSettings(const OnlineMatcherSettings& settings) {
  validate(settings);
  if (!keyframes_.empty()) {
    // Build the reference's grids with the new settings first: settings whose grids cannot be
    // built (the memory cap) throw here and leave the matcher as it was.
    CubeRegistration rebuilt(settings.registration);
    try {
      PointArray submap;
      submapPoints(keyframes_, settings.keyframes.submap_size, submap);
      rebuilt.setReference(submap);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("the current reference cannot be built with these "
                                              "settings: ") + e.what());
    }
    registration_ = std::move(rebuilt);
    while (keyframes_.size() > std::size_t(settings.keyframes.submap_size)) keyframes_.pop_front();
  } else {
    registration_.setSettings(settings.registration);
  }
  settings_ = settings;
}

double OnlineMatcher::gateScale(double stamp, double since) const {
  if (intervals_.empty()) return 1.0;
  // The scan period: the lower quartile of the recent intervals (the matcher sees longer ones
  // whenever scans are dropped; a few odd short ones do not move the quartile).
  std::vector<double> v(intervals_.begin(), intervals_.end());
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 4), v.end());
  const double period = v[v.size() / 4];
  // Whole periods: timing jitter does not widen the bounds, a missed scan does.
  return std::clamp(std::round((stamp - since) / period), 1.0, kMaxGateScale);
}

namespace {

void appendMessage(OnlineStep& step, const std::string& text) {
  if (!step.message.empty()) step.message += "; ";
  step.message += text;
}

/// Whether the points were taken over time (their times differ): only such a scan is de-skewed.
bool takenOverTime(const PointTimes* times) {
  if (!times || times->tau.empty()) return false;
  const auto [lo, hi] = std::minmax_element(times->tau.begin(), times->tau.end());
  return *hi - *lo > 1e-6f;
}

}  // namespace

void OnlineMatcher::deskewScan(OnlineStep& step, const PointArray& points,
                               const PointTimes& times, const SweepMotion& motion,
                               const Twist& placed, const GateSettings& gate_settings,
                               bool after_rejection, std::optional<PointArray>& out) {
  // The velocity the points were placed with (`placed`), and the registered one for an
  // increment keyframe -> scan (`motion`, core/deskew.h). The sweep re-placed with the motion
  // of `pose` (into `out`) and registered from there:
  const auto registerReplaced = [&](const Pose6& pose) {
    out = points;
    deskew(*out, times.tau, placed, motion.velocity(poseToIsometry(pose)));
    RegistrationResult result = registration_.align(*out, pose);
    countAlign(step.work, result);
    return result;
  };
  const Eigen::Isometry3d predicted_increment = step.increment;
  const auto start = std::chrono::steady_clock::now();
  const auto moved = [&](const Pose6& pose) {
    const Eigen::Isometry3d change = step.increment.inverse() * poseToIsometry(pose);
    return change.translation().norm() >= 1e-3 || Eigen::AngleAxisd(change.linear()).angle() >= 1.745e-4;
  };
  // Round 1: the pose at which every line lies on the reference (plane_polish.h), then a full
  // registration of the sweep re-placed there. Its verdict is the scan's, accepted or not: the
  // rigid registration of a bent sweep is a compromise between its lines that the gate accepts
  // where it is wrong (BENCHMARK.md, "Sweeps taken while driving"), so it only starts this.
  bool converged = false;  // round 1 moved the result less than 1 mm and 0.01 deg
  if (settings_.deskew.iterations >= 1) {
    ++step.work.deskew_rounds;
    const SweepPolishResult sp = registration_.polishSweep(points, times.tau, motion, placed,
                                                           step.result.pose, 20);
    RegistrationResult again;
    GateReason reason = GateReason::Uncertain;  // no polish: the sweep's motion is unknown
    if (sp.applied) {
      again = registerReplaced(sp.pose);
      reason = again.ok() ? gate(again, step.guess, gate_settings) : GateReason::BadInput;
    } else {
      appendMessage(step, "sweep polish not applied (" + sp.reason + ")");
    }
    step.accepted = reason == GateReason::Accepted;
    step.reason = reason;
    if (again.ok()) {
      converged = !moved(again.pose);
      step.result = std::move(again);
      if (step.accepted) {
        step.increment = step.result.transform;
        step.correction = correctionFromGuess(step.guess, step.result.pose);
        ++step.reregistered;
      }
    }
  }
  // Later rounds: the continuous-time polish again from the registered result (round 1's
  // rigid polish of the re-placed sweep was bound to the motion the sweep was re-placed with).
  // A polish that stays within the polish's shift limits is the round's result (the verdict,
  // J and covariance stay round 1's); one that moves further means round 1 had not converged:
  // the sweep re-placed there is registered again, kept if the gate accepts it.
  const PolishSettings& limits = settings_.registration.polish;
  for (int round = 1; step.accepted && !converged && round < settings_.deskew.iterations; ++round) {
    ++step.work.deskew_rounds;
    const SweepPolishResult sp = registration_.polishSweep(points, times.tau, motion, placed,
                                                           step.result.pose, 20);
    if (!sp.applied) break;
    if (sp.shift_m <= limits.max_shift_m && sp.shift_rad <= limits.max_shift_rad) {
      converged = !moved(sp.pose);
      step.result.pose = sp.pose;
      step.result.transform = poseToIsometry(sp.pose);
    } else {
      RegistrationResult again = registerReplaced(sp.pose);
      if (!again.ok() || gate(again, step.guess, gate_settings) != GateReason::Accepted) break;
      converged = !moved(again.pose);
      step.result = std::move(again);
    }
    step.increment = step.result.transform;
    step.correction = correctionFromGuess(step.guess, step.result.pose);
    ++step.reregistered;
  }
  if (step.accepted && after_rejection) {
    const std::string bent = bentSweep(step.result);
    if (!bent.empty()) {
      step.accepted = false;
      step.reason = GateReason::BentSweep;
      appendMessage(step, bent);
    }
  }
  step.work.deskew_s = secondsSince(start);
  if (!step.accepted) {
    step.increment = predicted_increment;
    out.reset();  // a rejected scan is never a keyframe's points
    return;
  }
  // The keyframe's points: re-placed with the final motion (from the scan as given).
  out = points;
  deskew(*out, times.tau, placed, motion.velocity(step.increment));
  step.deskewed = true;
}

std::string OnlineMatcher::bentSweep(const RegistrationResult& r) const {
  if (recent_fits_.empty() || !r.polished || r.points_used == 0) return {};
  const auto median = [&](double PlaneFit::*field) {
    std::vector<double> v;
    for (const PlaneFit& f : recent_fits_) v.push_back(f.*field);
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const PlaneFit fit = PlaneFit::of(r), recent{median(&PlaneFit::rms), median(&PlaneFit::fraction)};
  const DeskewSettings& d = settings_.deskew;
  std::ostringstream os;
  os.precision(3);
  if (d.max_rms_ratio > 0.0 && fit.rms > d.max_rms_ratio * recent.rms) {
    os << "plane RMS " << 100.0 * fit.rms << " cm > " << d.max_rms_ratio << " x the recent "
       << 100.0 * recent.rms << " cm";
  } else if (fit.fraction < d.min_plane_fraction_ratio * recent.fraction) {
    os << "points on planes " << fit.fraction << " < " << d.min_plane_fraction_ratio
       << " x the recent " << recent.fraction;
  } else {
    return {};
  }
  os << " after rejected scans: the sweep is still bent by a motion nothing registered";
  return os.str();
}

OnlineStep OnlineMatcher::process(const PointArray& points, double stamp,
                                  const std::optional<Eigen::Isometry3d>& given_odom,
                                  const PointTimes* times) {
  if (times && times->tau.size() != points.size()) {
    throw std::invalid_argument("process: " + std::to_string(times->tau.size()) +
                                " point times for " + std::to_string(points.size()) + " points");
  }
  if (!std::isfinite(stamp)) throw std::invalid_argument("process: the scan's stamp is not finite");
  const auto start = std::chrono::steady_clock::now();
  OnlineStep step;
  const std::optional<Eigen::Isometry3d> odom = usableOdometry(given_odom, step);
  // Whether the scan before this one is the last known one (none rejected in between), and
  // the odometry at the last scan that had one: the de-skew's motion model.
  const bool follows_known = last_known_ && last_stamp_ && *last_stamp_ == last_known_->stamp;
  const std::optional<Known> odom_before = previous_odom_;
  trackTime(stamp, step);
  const Twist placed = placedVelocity(stamp, odom, times);
  const bool first = keyframes_.empty();
  const Prediction predicted = predict(stamp, odom, step);
  const Keyframe* keyframe = first ? nullptr : &keyframes_.back();
  std::optional<PointArray> deskewed;  // the scan re-placed with the registered motion
  if (first) {
    step.reason = points.empty() ? GateReason::BadInput : GateReason::FirstScan;
    step.pose = predicted.pose;
  } else if (points.empty()) {
    step.reason = GateReason::BadInput;
  } else {
    registerAndGate(step, points, stamp, predicted.from, *keyframe);
    // A sweep taken over time is de-skewed whenever its rigid registration found a pose, even
    // one the gate rejected: the de-skewed registration decides.
    if (step.result.ok() && takenOverTime(times) && settings_.deskew.enabled && last_known_ &&
        stamp > last_known_->stamp) {
      SweepMotion motion;
      motion.anchor = last_known_->pose.inverse() * keyframe->pose;
      motion.interval = stamp - last_known_->stamp;
      if (!follows_known && odom && last_known_->odom && odom_before &&
          odom_before->stamp > last_known_->stamp && stamp > odom_before->stamp) {
        // Scans between were rejected: the odometry's shape of the motion since the known scan.
        motion.odometry_shaped = true;
        motion.odom_span = last_known_->odom->inverse() * *odom;
        motion.odom_own = odom_before->odom->inverse() * *odom;
        motion.own = stamp - odom_before->stamp;
      }
      deskewScan(step, points, *times, motion, placed, scaledGate(step.gate_scale), !follows_known,
                 deskewed);
    }
  }
  const bool refused = !placeScan(step, keyframe, predicted.pose);
  if (step.accepted && step.result.polished && step.result.points_used > 0) {
    recent_fits_.push_back(PlaneFit::of(step.result));
    if (recent_fits_.size() > kRecentFits) recent_fits_.pop_front();
  }
  countRejections(step, keyframe);
  updateChain(step, deskewed ? *deskewed : points, stamp, odom, keyframe, refused);
  if (deskewed) step.deskewed_points = std::move(*deskewed);
  describe(step);
  step.work.total_s = secondsSince(start);
  return step;
}

std::optional<Eigen::Isometry3d> OnlineMatcher::usableOdometry(
    const std::optional<Eigen::Isometry3d>& odom, OnlineStep& step) {
  // Odometry with a NaN or infinite value (a broken driver) is no odometry.
  if (odom && !isRigid(*odom)) {
    appendMessage(step, "odometry pose not finite or not a rotation: ignored");
    return std::nullopt;
  }
  return odom;
}

void OnlineMatcher::trackTime(double stamp, OnlineStep& step) {
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
}

Twist OnlineMatcher::placedVelocity(double stamp, const std::optional<Eigen::Isometry3d>& odom,
                                    const PointTimes* times) {
  // The velocity the odometry placed this scan's points with: its motion since the previous
  // scan (whatever became of that one), at constant velocity (core/deskew.h).
  Twist placed = Twist::Zero();
  if (times && times->placed_by_odometry && odom && previous_odom_ && stamp > previous_odom_->stamp) {
    placed = velocityOf(previous_odom_->odom->inverse() * *odom, stamp - previous_odom_->stamp);
  }
  if (odom) previous_odom_ = Known{Eigen::Isometry3d::Identity(), odom, stamp};
  return placed;
}

OnlineMatcher::Prediction OnlineMatcher::predict(double stamp,
                                                 const std::optional<Eigen::Isometry3d>& odom,
                                                 OnlineStep& step) const {
  // The predicted pose T_map_base: the first scan's start pose or odometry; then the odometry
  // increment from the anchor, else the last known pose moved on at the last registered
  // velocity (constant_velocity) or not moved.
  const bool first = keyframes_.empty();
  step.odometry_guess = !first && odom && anchor_;
  Prediction p{start_pose_ ? *start_pose_ : odom ? *odom : Eigen::Isometry3d::Identity(), stamp};
  if (step.odometry_guess) {
    p.pose = anchor_->pose * anchor_->odom->inverse() * *odom;
    p.from = anchor_->stamp;
  } else if (!first && last_known_) {
    p.pose = last_known_->pose;
    if (settings_.constant_velocity) {
      p.pose = p.pose * poseToIsometry(velocity_ * (stamp - last_known_->stamp));
    }
    p.from = last_known_->stamp;
  }
  if (!first) step.increment = keyframes_.back().pose.inverse() * p.pose;
  step.guess = isometryToPose(step.increment);
  return p;
}

GateSettings OnlineMatcher::scaledGate(double gate_scale) const {
  GateSettings g = settings_.gate;
  g.max_correction_m *= gate_scale;
  g.max_correction_rad *= gate_scale;
  return g;
}

void OnlineMatcher::registerAndGate(OnlineStep& step, const PointArray& points, double stamp,
                                    double predicted_from, const Keyframe& keyframe) {
  step.registered = true;
  step.gate_scale = gateScale(stamp, predicted_from);
  if (!step.odometry_guess) step.gate_scale = std::max(step.gate_scale, settings_.no_odometry_scale);
  const bool grid = !step.odometry_guess && settings_.no_odometry_grid.enabled() && last_known_;
  // The guess spans several increments, or has no odometry: search as much wider as the gate
  // is (without odometry, with the planar grid instead when it is on).
  RegistrationSettings wide = settings_.registration;
  if (grid) {
    // A turn on the spot goes on while its scans are rejected: each one widens the yaw range.
    wide.search.grid = settings_.no_odometry_grid;
    wide.search.grid.half_yaw = std::min(double(EIGEN_PI), wide.search.grid.half_yaw *
                                                               (1.0 + consecutive_rejections_));
    wide.dense_points = settings_.no_odometry_dense_points;
    wide.dense_refine = true;
  } else {
    wide.gnmm.bounds *= step.gate_scale;
  }
  const bool widened = step.gate_scale > 1.0 || grid;
  if (widened) registration_.setSettings(wide);
  auto start = std::chrono::steady_clock::now();
  const Pose6 grid_centre = grid ? stillPose(keyframe) : step.guess;  // "no motion"
  step.result = registration_.align(points, step.guess, grid_centre);
  countAlign(step.work, step.result);
  step.work.register_s = secondsSince(start);
  if (grid && step.result.ok()) {
    // The grid searched around "no motion" as well as around the prediction: the correction
    // is measured from the nearer of the two.
    const Pose6& still = grid_centre;
    if (correctionSize(still, step.result.pose, settings_.gate) <
        correctionSize(step.guess, step.result.pose, settings_.gate)) {
      step.guess = still;
    }
  }
  if (!grid && !step.odometry_guess && settings_.constant_velocity &&
      settings_.no_motion_candidate && last_known_) {
    // Constant velocity fails where the motion changes most (a turn on the spot that starts,
    // stops or reverses): the no-motion guess is searched too, and the higher J wins.
    const Pose6 still = stillPose(keyframe);
    if ((still - step.guess).norm() > 1e-6) {
      start = std::chrono::steady_clock::now();
      RegistrationResult other = registration_.align(points, still);
      countAlign(step.work, other);
      step.work.candidate_s = secondsSince(start);
      if (other.ok() && (!step.result.ok() || other.J > step.result.J)) {
        step.result = std::move(other);
        step.guess = still;
      }
    }
  }
  GateSettings gate_settings = scaledGate(step.gate_scale);
  if (grid) {
    // The grid searched this far around "no motion": a result within it is no large correction.
    gate_settings.max_correction_rad = std::max(gate_settings.max_correction_rad,
                                                wide.search.grid.half_yaw + wide.search.grid.step_yaw);
  }
  step.reason = gate(step.result, step.guess, gate_settings);
  const bool dense_searched =
      searchDenseAtNoMotion(step, points, keyframe, widened ? wide : settings_.registration);
  if (widened || dense_searched) registration_.setSettings(settings_.registration);
  if (step.result.ok()) step.correction = correctionFromGuess(step.guess, step.result.pose);
  step.accepted = step.reason == GateReason::Accepted;
  if (step.accepted) step.increment = step.result.transform;
}

Pose6 OnlineMatcher::stillPose(const Keyframe& keyframe) const {
  return isometryToPose(keyframe.pose.inverse() * last_known_->pose);
}

bool OnlineMatcher::searchDenseAtNoMotion(OnlineStep& step, const PointArray& points,
                                          const Keyframe& keyframe,
                                          const RegistrationSettings& searched) {
  // J over all points peaks at no motion (the scan on the last scan's own sampling pattern);
  // on the densely sampled points it peaks at the truth. The gate rejects most such results
  // (weakly fixed along the path); the odometry's guess says where to search again.
  if (!step.odometry_guess || step.reason == GateReason::Accepted ||
      settings_.no_motion_dense_points == 0 || searched.dense_points > 0 || !step.result.ok() ||
      !last_known_) {
    return false;
  }
  const double edge = searched.grid.cube_edge;
  if (!posesWithin(step.result.pose, stillPose(keyframe), edge / 2.0, deg2rad(2.0))) return false;
  RegistrationSettings dense = searched;
  dense.dense_points = settings_.no_motion_dense_points;
  registration_.setSettings(dense);
  const auto start = std::chrono::steady_clock::now();
  RegistrationResult other = registration_.align(points, step.guess);
  countAlign(step.work, other);
  step.work.candidate_s += secondsSince(start);
  const GateReason verdict = gate(other, step.guess, scaledGate(step.gate_scale));
  if (verdict == GateReason::Accepted) {
    step.result = std::move(other);
    step.reason = verdict;
  }
  return true;
}

bool OnlineMatcher::placeScan(OnlineStep& step, const Keyframe* keyframe,
                              const Eigen::Isometry3d& predicted) {
  // A rejected scan is placed at the prediction itself: keyframe * (keyframe^-1 * predicted)
  // would multiply the keyframe's rounding error into the pose, and a chain of forced scans
  // (each the next one's keyframe) would grow it threefold per scan until the pose is NaN.
  if (keyframe) step.pose = step.accepted ? keyframe->pose * step.increment : predicted;
  // The chain guard: a pose that is not a finite rigid motion never enters the chain, the
  // prediction or a published message; the scan is refused and the last pose kept.
  if (isRigid(step.pose)) return true;
  step.reason = GateReason::NonFinite;
  step.accepted = false;
  step.pose = last_known_ ? last_known_->pose : last_pose_;
  step.increment = keyframe ? keyframe->pose.inverse() * step.pose : Eigen::Isometry3d::Identity();
  appendMessage(step, "the step's pose is not a finite rigid motion: refused, the last pose kept");
  return false;
}

void OnlineMatcher::countRejections(OnlineStep& step, const Keyframe* keyframe) {
  const bool rejected = keyframe && !step.accepted;  // the first scan (no keyframe) is never rejected
  consecutive_rejections_ = rejected ? consecutive_rejections_ + 1 : 0;
  step.consecutive_rejections = consecutive_rejections_;
  step.rejection_alarm = consecutive_rejections_ >= settings_.max_consecutive_rejections;
}

void OnlineMatcher::updateChain(OnlineStep& step, const PointArray& points, double stamp,
                                const std::optional<Eigen::Isometry3d>& odom,
                                const Keyframe* keyframe, bool refused) {
  const bool first = !keyframe;
  // A known pose (first, accepted, or forced on by the alarm) predicts the next scans.
  const bool known = !refused && (first || step.accepted || (step.rejection_alarm && !points.empty()));
  if (known && !points.empty()) {
    if (last_known_ && stamp > last_known_->stamp) {
      step.motion = last_known_->pose.inverse() * step.pose;
      step.interval = stamp - last_known_->stamp;
      const Pose6 velocity = isometryToPose(step.motion) / step.interval;
      if (velocity.allFinite()) velocity_ = velocity;
    }
    // A new keyframe: the first scan, a forced one, or an accepted scan far enough from the
    // keyframe (never a rejected one).
    bool new_keyframe = first || !step.accepted;
    if (!new_keyframe) {
      const KeyframeSettings& k = settings_.keyframes;
      const double moved = step.increment.translation().norm();
      const double turned = Eigen::AngleAxisd(step.increment.linear()).angle();
      new_keyframe = moved >= k.distance || turned >= k.angle ||
                     (k.interval > 0.0 && stamp - keyframe->stamp >= k.interval);
    }
    std::string why;
    const auto start = std::chrono::steady_clock::now();
    const bool added = new_keyframe && addKeyframe(points, step.pose, stamp, why);
    if (new_keyframe) {
      step.work.reference_built = added;
      step.work.reference_s = secondsSince(start);
    }
    if (new_keyframe && !added) {
      if (first) step.reason = GateReason::BadReference;
      appendMessage(step, "scan not used as reference: " + why);
    } else {
      step.reference_updated = new_keyframe;
    }
    if (!first || step.reference_updated) {
      last_known_ = Known{step.pose, odom, stamp};
      if (odom) anchor_ = last_known_;
      if (first) start_pose_.reset();
    }
  } else if (!first && !step.accepted && !points.empty() && !refused) {
    appendMessage(step, "scan not used as reference: the registration was rejected");
  }
  step.keyframes = int(keyframes_.size());  // at most submap_size: addKeyframe(), setSettings()
  last_pose_ = step.pose;
}

void OnlineMatcher::describe(OnlineStep& step) {
  std::ostringstream os;
  os << toString(step.reason);
  if (step.registered) os << " (" << step.result.message << ")";
  if (step.deskewed) os << "; de-skewed (" << step.reregistered << " rounds)";
  if (step.gate_scale > 1.0) {
    os << "; correction bounds x" << step.gate_scale
       << (step.odometry_guess ? " (scans missed)" : " (no odometry)");
  }
  if (!step.message.empty()) os << "; " << step.message;
  step.message = os.str();
}

}  // namespace cube_scan_matcher
