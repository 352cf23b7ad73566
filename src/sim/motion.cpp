#include "cube_scan_matcher/sim/motion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher::sim {
namespace {

double uniform(std::mt19937_64& rng, double half) {
  return std::uniform_real_distribution<double>(-half, half)(rng);
}

}  // namespace

Eigen::Isometry3d randomTransform(std::mt19937_64& rng, double t, double a_deg) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.translation() = Eigen::Vector3d(uniform(rng, t), uniform(rng, t), uniform(rng, t));
  e.linear() = rotationFromRpy(deg2rad(uniform(rng, a_deg)), deg2rad(uniform(rng, a_deg)),
                               deg2rad(uniform(rng, a_deg)));
  return e;
}

RobotMotion::RobotMotion(const Scene& scene, const MotionSettings& settings, std::uint64_t seed)
    : scene_(scene), s_(settings), rng_(seed) {
  heading_ = deg2rad(uniform(rng_, s_.heading_max_deg));
  place();
}

void RobotMotion::place() {
  pose_.linear() = rotationFromRpy(deg2rad(uniform(rng_, s_.tilt_max_deg)),
                                   deg2rad(uniform(rng_, s_.tilt_max_deg)), heading_);
  pose_.translation() = Eigen::Vector3d(x_, y_, scene_.groundHeight(x_, y_) + s_.height);
}

void RobotMotion::advance() {
  double step = std::uniform_real_distribution<double>(s_.step_min, s_.step_max)(rng_);
  const double base = dir_ > 0 ? 0.0 : M_PI;
  if (turning_ > 0) {
    heading_ += deg2rad(45.0);
    step = 1.0;
    --turning_;
  } else if ((dir_ > 0 && x_ > s_.x_max) || (dir_ < 0 && x_ < s_.x_min)) {
    dir_ = -dir_;
    turning_ = 3;
    heading_ += deg2rad(45.0);
    step = 1.0;
  } else {
    const double hmax = deg2rad(s_.heading_max_deg);
    double rel = wrapAngle(heading_ - base) + deg2rad(uniform(rng_, s_.yaw_change_max_deg));
    rel = std::clamp(rel, -hmax, hmax);
    if (std::abs(y_) > s_.lateral_limit) rel = (y_ * dir_ > 0 ? -1.0 : 1.0) * std::abs(rel);
    heading_ = base + rel;
  }
  heading_ = wrapAngle(heading_);
  x_ += step * std::cos(heading_);
  y_ += step * std::sin(heading_);
  place();
}

OdometryError odometryErrorFromString(const std::string& name) {
  if (name == "none") return OdometryError::None;
  if (name == "small") return OdometryError::Small;
  if (name == "big") return OdometryError::Big;
  if (name == "drift") return OdometryError::Drift;
  throw std::invalid_argument("odometry error mode must be none, small, big or drift, got '" +
                              name + "'");
}

OdometrySimulator::OdometrySimulator(OdometryError mode, std::uint64_t seed)
    : mode_(mode), rng_(seed) {}

Eigen::Isometry3d OdometrySimulator::next(const Eigen::Isometry3d& truth) {
  Eigen::Isometry3d odom = truth;
  if (!first_) {
    const Eigen::Isometry3d increment = last_truth_.inverse() * truth;
    switch (mode_) {
      case OdometryError::None: odom = last_odom_ * increment; break;
      case OdometryError::Small: odom = last_odom_ * increment * randomTransform(rng_, 0.25, 2.0); break;
      case OdometryError::Big: odom = last_odom_ * increment * randomTransform(rng_, 1.0, 8.0); break;
      case OdometryError::Drift:
        bias_ = bias_ * randomTransform(rng_, 0.05, 0.3);
        odom = truth * bias_;
        break;
    }
  }
  first_ = false;
  last_truth_ = truth;
  last_odom_ = odom;
  return odom;
}

}  // namespace cube_scan_matcher::sim
