#include "cube_scan_matcher/assembly/sweep_cutter.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cube_scan_matcher {

void validate(const SweepCutterSettings& s) {
  auto fail = [](const std::string& name, double value, const std::string& rule) {
    std::ostringstream os;
    os << "SweepCutterSettings::" << name << " = " << value << " must be " << rule;
    throw std::invalid_argument(os.str());
  };
  // Written so that NaN fails each test.
  if (!(s.turn_hysteresis >= 0.0 && s.turn_hysteresis < M_PI)) {
    fail("turn_hysteresis", s.turn_hysteresis, "in [0, pi) rad");
  }
  if (!(s.sweep_duration >= 0.0 && std::isfinite(s.sweep_duration))) {
    fail("sweep_duration", s.sweep_duration, ">= 0 s (0 = off)");
  }
  if (!(s.stall_timeout >= 0.0 && std::isfinite(s.stall_timeout))) {
    fail("stall_timeout", s.stall_timeout, ">= 0 s (0 = off)");
  }
  if (!(s.max_line_gap > 0.0 && std::isfinite(s.max_line_gap))) {
    fail("max_line_gap", s.max_line_gap, "> 0 s");
  }
  if (s.min_lines < 1) fail("min_lines", s.min_lines, ">= 1");
  if (s.max_lines < s.min_lines) fail("max_lines", s.max_lines, ">= min_lines");
}

std::string toString(CutReason reason) {
  switch (reason) {
    case CutReason::None: return "none";
    case CutReason::TurningPoint: return "turning point";
    case CutReason::Duration: return "sweep_duration elapsed";
    case CutReason::Stall: return "tilt stalled";
    case CutReason::Stalled: return "tilt still stalled";
    case CutReason::MaxLines: return "max_lines reached";
    case CutReason::Gap: return "gap between lines";
    case CutReason::TimeBackwards: return "time went backwards";
    case CutReason::LateLine: return "late line";
  }
  return "unknown";
}

SweepCutter::SweepCutter(const SweepCutterSettings& settings) : settings_(settings) {
  validate(settings_);
}

void SweepCutter::reset() {
  pending_.clear();
  newest_time_.reset();
  last_angle_.reset();
  direction_ = 0;
  has_reference_ = false;
  anchor_angle_.reset();
  stalled_ = false;
}

double SweepCutter::unwrap(double angle) {
  if (last_angle_) angle = *last_angle_ + std::remainder(angle - *last_angle_, 2.0 * M_PI);
  last_angle_ = angle;
  return angle;
}

bool SweepCutter::updateTurn(std::size_t index, double a) {
  const double h = settings_.turn_hysteresis;
  if (!has_reference_) {
    has_reference_ = true;
    reference_angle_ = extreme_angle_ = a;
    extreme_index_ = index;
    return false;
  }
  if (direction_ == 0) {
    // The direction is not known yet: it is the first move by more than h from the sweep's
    // first angle, and that line is the extreme so far.
    if (a > reference_angle_ + h) {
      direction_ = 1;
    } else if (a < reference_angle_ - h) {
      direction_ = -1;
    } else {
      return false;
    }
    extreme_angle_ = a;
    extreme_index_ = index;
    return false;
  }
  if (direction_ * (a - extreme_angle_) > 0.0) {
    extreme_angle_ = a;
    extreme_index_ = index;
    return false;
  }
  return direction_ * (extreme_angle_ - a) > h;
}

void SweepCutter::restartTurnDetector(int direction) {
  direction_ = direction;
  has_reference_ = false;
  // A cut found while replaying (the carried lines reversed again by more than h) is found
  // again by the next line, whose test uses the same extreme.
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    if (pending_[i].angle) updateTurn(i, *pending_[i].angle);
  }
}

CutResult SweepCutter::close(std::size_t n, CutReason reason) {
  CutResult r;
  if (n == 0 && reason != CutReason::TimeBackwards) return r;  // nothing was closed
  r.reason = reason;
  r.closed_lines = n;
  r.event = n >= std::size_t(settings_.min_lines) ? CutEvent::SweepEnded : CutEvent::Discarded;
  pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(n));
  return r;
}

CutResult SweepCutter::addLine(double time, std::optional<double> angle) {
  if (!std::isfinite(time)) throw std::invalid_argument("SweepCutter::addLine: time is not finite");
  if (angle && !std::isfinite(*angle)) angle.reset();
  const SweepCutterSettings& s = settings_;

  if (newest_time_ && (time < *newest_time_ || time - *newest_time_ > s.max_line_gap)) {
    if (time < *newest_time_ && *newest_time_ - time <= s.max_line_gap) {
      CutResult late;  // state unchanged: the line is not used
      late.event = CutEvent::Discarded;
      late.reason = CutReason::LateLine;
      late.line_kept = false;
      return late;
    }
    // A gap, or time going backwards: close what there is and start afresh with this line.
    const CutReason reason = time < *newest_time_ ? CutReason::TimeBackwards : CutReason::Gap;
    CutResult r = close(pending_.size(), reason);
    reset();
    newest_time_ = time;
    pending_.push_back({time, angle ? std::optional<double>(unwrap(*angle)) : std::nullopt});
    if (angle) {
      updateTurn(0, *pending_.back().angle);
      anchor_angle_ = pending_.back().angle;
      anchor_time_ = time;
    }
    return r;
  }
  newest_time_ = time;
  const std::optional<double> a = angle ? std::optional<double>(unwrap(*angle)) : std::nullopt;
  const double h = s.turn_hysteresis;

  if (stalled_) {
    if (a && std::abs(*a - *anchor_angle_) > h) {  // moving again: a new sweep starts here
      stalled_ = false;
      anchor_angle_ = a;
      anchor_time_ = time;
      pending_.push_back({time, a});
      restartTurnDetector(0);
      return CutResult{};
    }
    CutResult r;
    r.event = CutEvent::Discarded;
    r.reason = CutReason::Stalled;
    r.line_kept = false;
    return r;
  }

  CutResult r;
  if (s.sweep_duration > 0.0 && !pending_.empty() &&
      time - pending_.front().time >= s.sweep_duration) {
    // The sweep is [first line, first line + sweep_duration): this line starts the next. The
    // tilt keeps its direction across the cut, so a turning point just after it is not missed.
    r = close(pending_.size(), CutReason::Duration);
    restartTurnDetector(direction_);
  }
  pending_.push_back({time, a});
  if (pending_.size() >= std::size_t(s.max_lines)) {  // (a duration cut leaves one line)
    const int direction = direction_;
    r = close(pending_.size(), CutReason::MaxLines);
    restartTurnDetector(direction);
    return r;
  }
  if (!a) return r;

  if (s.stall_timeout > 0.0) {
    if (!anchor_angle_ || std::abs(*a - *anchor_angle_) > h) {
      anchor_angle_ = a;
      anchor_time_ = time;
    } else if (time - anchor_time_ >= s.stall_timeout && r.event == CutEvent::Continue) {
      // (After a duration cut on this very line the stall is found by the next line.)
      stalled_ = true;
      return close(pending_.size(), CutReason::Stall);
    }
  }

  const bool turn = updateTurn(pending_.size() - 1, *a);
  if (turn && r.event == CutEvent::Continue) {
    // The sweep ends with the line at the extreme; the lines after it start the next sweep,
    // which moves the other way.
    const int direction = direction_;
    r = close(extreme_index_ + 1, CutReason::TurningPoint);
    restartTurnDetector(-direction);
  }
  return r;
}

}  // namespace cube_scan_matcher
