#include "cube_scan_matcher/sim/sequence_motion.h"

#include <algorithm>
#include <cmath>

#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/sim/motion.h"

namespace cube_scan_matcher::sim {

SequenceMotion::SequenceMotion(const Scene& scene, const SequenceSettings& settings,
                               std::uint64_t seed)
    : scene_(scene), s_(settings), rng_(seed) {
  left_ = s_.drive_sweeps;
  place();
}

bool SequenceMotion::clear(double x, double y) const {
  const double ground = scene_.groundHeight(x, y);
  for (const double h : {0.2, 0.6, s_.height}) {
    if (scene_.insideSolid(Eigen::Vector3d(x, y, ground + h), s_.clearance)) return false;
  }
  return true;
}

void SequenceMotion::place() { pose_ = placeOnGround(scene_, x_, y_, heading_, s_.height); }

void SequenceMotion::advance() {
  const double turn = deg2rad(s_.turn_step_deg);
  const int quarter = std::max(1, int(std::lround(90.0 / s_.turn_step_deg)));
  auto next = [&](Phase p, int sweeps) { phase_ = p, left_ = sweeps; };
  switch (phase_) {
    case Phase::Drive: {
      const bool beyond = (axis_ == 0.0 && x_ > s_.x_max) || (axis_ != 0.0 && x_ < s_.x_min);
      if (beyond) {
        next(Phase::TurnRound, 2 * quarter);
        axis_ = axis_ == 0.0 ? M_PI : 0.0;
        return advance();
      }
      if (left_-- <= 0) {
        next(Phase::Stand, s_.stand_sweeps);
        return advance();
      }
      const double jitter = deg2rad(s_.heading_jitter_deg), hmax = deg2rad(s_.heading_max_deg);
      double rel = wrapAngle(heading_ - axis_) + std::uniform_real_distribution<double>(-jitter, jitter)(rng_);
      rel = std::clamp(rel, -hmax, hmax);
      const double side = axis_ == 0.0 ? 1.0 : -1.0;  // +y is left when driving along +x
      if (std::abs(y_) > s_.lateral_limit) rel = (y_ * side > 0 ? -1.0 : 1.0) * std::abs(rel);
      // The first heading from the planned one (then 10, 20, ... 60 deg to either side) whose
      // step ends clear of every solid; none: turn round here.
      bool moved = false;
      for (int k = 0; k <= 12; ++k) {
        const double offset = deg2rad(10.0 * double((k + 1) / 2)) * (k % 2 == 0 ? -1.0 : 1.0);
        const double h = wrapAngle(axis_ + rel + offset);
        const double x = x_ + s_.step * std::cos(h), y = y_ + s_.step * std::sin(h);
        if (!clear(x, y)) continue;
        heading_ = h, x_ = x, y_ = y;
        moved = true;
        break;
      }
      if (!moved) {
        next(Phase::TurnRound, 2 * quarter);
        axis_ = axis_ == 0.0 ? M_PI : 0.0;
        return advance();
      }
      break;
    }
    case Phase::Stand:
      if (left_-- <= 0) {
        next(Phase::LookOut, quarter);
        return advance();
      }
      break;
    case Phase::LookOut:
      heading_ = wrapAngle(heading_ + look_ * turn);
      if (--left_ <= 0) next(Phase::LookBack, quarter);
      break;
    case Phase::LookBack:
      heading_ = wrapAngle(heading_ - look_ * turn);
      if (--left_ <= 0) next(Phase::Drive, s_.drive_sweeps), look_ = -look_;
      break;
    case Phase::TurnRound:
      heading_ = wrapAngle(heading_ + turn);
      if (--left_ <= 0) {
        heading_ = axis_;
        next(Phase::Drive, s_.drive_sweeps);
      }
      break;
  }
  place();
}

}  // namespace cube_scan_matcher::sim
