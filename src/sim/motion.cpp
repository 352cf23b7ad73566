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

Eigen::Isometry3d placeOnGround(const Scene& scene, double x, double y, double heading, double height) {
  // Pitch and roll of a robot standing on the ground: the slope over its 1 m footprint.
  const double h = 0.5, c = std::cos(heading), s = std::sin(heading);
  const double z = scene.groundHeight(x, y);
  const double front = scene.groundHeight(x + h * c, y + h * s) - scene.groundHeight(x - h * c, y - h * s);
  const double left = scene.groundHeight(x - h * s, y + h * c) - scene.groundHeight(x + h * s, y - h * c);
  const double pitch = -std::atan2(front, 2 * h), roll = std::atan2(left, 2 * h);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotationFromRpy(roll, pitch, heading);
  pose.translation() = Eigen::Vector3d(x, y, z + height);
  return pose;
}

DrivenPath::DrivenPath(const Scene& scene, const DrivenPathSettings& settings, double x0, double y0,
                       double heading0)
    : scene_(scene), s_(settings), x0_(x0), y0_(y0), h0_(heading0) {
  if (!(s_.interval > 0.0)) throw std::invalid_argument("DrivenPath: interval must be > 0 s");
}

Eigen::Isometry3d DrivenPath::at(double t) const {
  const double v = s_.speed, w = deg2rad(s_.yaw_rate_deg), dt = s_.interval;
  double x = x0_, y = y0_, h = h0_ - 0.5 * w * dt;
  // Closed-form arcs, one per interval of constant yaw rate (+w, -w, +w, ...).
  for (int k = 0; t > 0.0; ++k) {
    const double d = std::min(t, dt), rate = k % 2 == 0 ? w : -w;
    if (std::abs(rate) < 1e-12) {
      x += v * d * std::cos(h);
      y += v * d * std::sin(h);
    } else {
      x += v / rate * (std::sin(h + rate * d) - std::sin(h));
      y -= v / rate * (std::cos(h + rate * d) - std::cos(h));
      h += rate * d;
    }
    t -= d;
  }
  return placeOnGround(scene_, x, y, h, s_.height);
}

Eigen::Isometry3d randomTransform(std::mt19937_64& rng, double t, double a_deg) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.translation() = Eigen::Vector3d(uniform(rng, t), uniform(rng, t), uniform(rng, t));
  e.linear() = rotationFromRpy(deg2rad(uniform(rng, a_deg)), deg2rad(uniform(rng, a_deg)),
                               deg2rad(uniform(rng, a_deg)));
  return e;
}

Eigen::Isometry3d paperTable1Motion(SceneType type) {
  struct Row {
    double x0, y0, z0, alpha, beta, gamma;  // [m], [deg]: Table 1, the paper's frame
  };
  Row r{};
  switch (type) {
    case SceneType::Hall:
    case SceneType::Tunnel: r = {-2.570, 3.144, -0.029, -20.858, 1.651, 5.999}; break;
    case SceneType::Urban:
    case SceneType::Square:
    case SceneType::Wall:
    case SceneType::Crowd: r = {0.406, 3.662, 0.053, 27.126, 5.282, -6.127}; break;
    case SceneType::Park:
    case SceneType::Forest: r = {2.541, 4.696, 0.133, -44.106, -0.717, 6.294}; break;
    case SceneType::Natural:
    case SceneType::Slope: r = {0.732, 2.516, -0.049, -1.675, -14.666, -2.258}; break;
  }
  Eigen::Isometry3d paper = Eigen::Isometry3d::Identity();
  paper.translation() = Eigen::Vector3d(r.x0, r.y0, r.z0);
  paper.linear() = (Eigen::AngleAxisd(deg2rad(r.alpha), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(deg2rad(r.beta), Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(deg2rad(r.gamma), Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();  // paper frame -> simulator frame
  m.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return m * paper * m.inverse();
}

Eigen::Isometry3d randomPairMotion(std::mt19937_64& rng) {
  const double travel = std::uniform_real_distribution<double>(1.0, 5.0)(rng);
  const double yaw = deg2rad(uniform(rng, 45.0));
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(travel * std::cos(yaw / 2), travel * std::sin(yaw / 2),
                                    uniform(rng, 0.1));
  t.linear() = rotationFromRpy(deg2rad(uniform(rng, 2.0)), deg2rad(uniform(rng, 2.0)), yaw);
  return t;
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
  if (name == "dgps") return OdometryError::Dgps;
  throw std::invalid_argument("odometry error mode must be none, small, big, drift or dgps, got '" +
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
      case OdometryError::Dgps: {
        // o_k = a o_(k-1) + sqrt(1 - a^2) sd n_k keeps the offset's sd at `sd` once stationary.
        const double a = std::exp(-1.0 / 20.0), b = std::sqrt(1.0 - a * a);
        const double sd[6] = {0.3, 0.3, 0.3, deg2rad(0.2), deg2rad(0.2), deg2rad(0.5)};
        std::normal_distribution<double> n(0.0, 1.0);
        for (int i = 0; i < 6; ++i) offset_(i) = a * offset_(i) + b * sd[i] * n(rng_);
        odom.translation() = truth.translation() + offset_.head<3>();
        odom.linear() = rotationFromRpy(offset_(3), offset_(4), offset_(5)) * truth.linear();
        break;
      }
    }
  }
  first_ = false;
  last_truth_ = truth;
  last_odom_ = odom;
  return odom;
}

}  // namespace cube_scan_matcher::sim
