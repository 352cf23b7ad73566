#include "cube_scan_matcher/core/deskew.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cube_scan_matcher {
namespace {

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(),  //
      w.z(), 0, -w.x(),   //
      -w.y(), w.x(), 0;
  return m;
}

/// V of the SE(3) exponential (t = V rho): I + (1 - cos a)/a^2 W + (a - sin a)/a^3 W^2.
Eigen::Matrix3d leftJacobian(const Eigen::Vector3d& w) {
  const double a = w.norm();
  const Eigen::Matrix3d W = hat(w);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(a)) / (a * a) * W +
         (a - std::sin(a)) / (a * a * a) * W * W;
}

}  // namespace

Twist logMotion(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  Twist xi;
  xi.tail<3>() = w;
  xi.head<3>() = leftJacobian(w).inverse() * T.translation();
  return xi;
}

Eigen::Isometry3d expMotion(const Twist& xi) {
  const Eigen::Vector3d w = xi.tail<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double a = w.norm();
  if (a > 0.0) T.linear() = Eigen::AngleAxisd(a, w / a).toRotationMatrix();
  T.translation() = leftJacobian(w) * xi.head<3>();
  return T;
}

Eigen::Isometry3d motionAt(const Twist& xi, double tau, double interval) {
  return expMotion(xi * (tau / interval));
}

Twist velocityOf(const Eigen::Isometry3d& motion, double interval) {
  return interval > 0.0 ? Twist(logMotion(motion) / interval) : Twist(Twist::Zero());
}

Twist SweepMotion::velocity(const Eigen::Isometry3d& T) const {
  if (!odometry_shaped) return velocityOf(anchor * T, interval);
  const Eigen::Isometry3d correction = odom_span.inverse() * (anchor * T);
  return velocityOf(odom_own * expMotion(logMotion(correction) * (own / interval)), own);
}

void deskew(PointArray& points, const std::vector<float>& tau, const Twist& placed,
            const Twist& truth) {
  if (tau.size() != points.size()) {
    throw std::invalid_argument("deskew: " + std::to_string(tau.size()) + " time offsets for " +
                                std::to_string(points.size()) + " points");
  }
  float last_tau = 0.0f;
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i == 0 || tau[i] != last_tau) {
      last_tau = tau[i];
      const Eigen::Isometry3d c = expMotion(truth * tau[i]) * expMotion(placed * tau[i]).inverse();
      R = c.linear().cast<float>();
      t = c.translation().cast<float>();
    }
    const Eigen::Vector3f q = R * points.point(i) + t;
    points.x[i] = q.x(), points.y[i] = q.y(), points.z[i] = q.z();
  }
}

}  // namespace cube_scan_matcher
