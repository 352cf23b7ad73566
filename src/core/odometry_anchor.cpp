#include "cube_scan_matcher/core/odometry_anchor.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

#include "cube_scan_matcher/core/vector6.h"

namespace cube_scan_matcher {

void validate(const OdometryAnchorSettings& s) {
  if (!(s.odometry_sigma_m > 0.0) || !std::isfinite(s.odometry_sigma_m) ||
      !(s.odometry_sigma_rad > 0.0) || !std::isfinite(s.odometry_sigma_rad)) {
    throw std::invalid_argument(
        "odometry anchor: odometry_sigma_m and odometry_sigma_rad must be finite and > 0");
  }
}

OdometryAnchor::OdometryAnchor(const OdometryAnchorSettings& settings) : settings_(settings) {
  validate(settings_);
}

void OdometryAnchor::setSettings(const OdometryAnchorSettings& settings) {
  validate(settings);
  settings_ = settings;
}

void OdometryAnchor::reset(const std::optional<Matrix6d>& start_covariance) {
  last_chain_.reset();
  start_covariance_ = start_covariance;
}

Eigen::Isometry3d OdometryAnchor::add(const Eigen::Isometry3d& chain_pose,
                                      const Matrix6d& motion_covariance,
                                      const std::optional<Eigen::Isometry3d>& odom) {
  const Matrix6d R = diagonalCovariance(settings_.odometry_sigma_m, settings_.odometry_sigma_rad);
  if (!last_chain_) {
    pose_ = odom && !start_covariance_ ? *odom : chain_pose;
    covariance_ = start_covariance_ ? *start_covariance_ : R;
    start_covariance_.reset();
    last_chain_ = chain_pose;
    return pose_;
  }
  // Prediction: the chain's motion since the last scan, applied to the anchored pose; the
  // heading error moves the position through the motion's lever arm (compoundCovariance).
  const Eigen::Isometry3d motion = last_chain_->inverse() * chain_pose;
  // The chain's map axes seen from the anchored frame's: the rotation between the two poses
  // of the last scan.
  const Eigen::Matrix3d R_anchor_map = pose_.linear() * last_chain_->linear().transpose();
  last_chain_ = chain_pose;
  const Eigen::Isometry3d predicted = pose_ * motion;
  const Matrix6d motion_in_anchor = rotateCovariance(motion_covariance, R_anchor_map);
  covariance_ = compoundCovariance(covariance_, motion_in_anchor,
                                   predicted.translation() - pose_.translation());
  pose_ = predicted;
  if (!odom) return pose_;
  // Update with the odometry pose: innovation [t_odom - t, log(R_odom R^T)].
  Vector6d innovation;
  innovation.head<3>() = odom->translation() - pose_.translation();
  const Eigen::AngleAxisd d(odom->linear() * pose_.linear().transpose());
  innovation.tail<3>() = d.axis() * d.angle();
  const Matrix6d gain = covariance_ * (covariance_ + R).inverse();
  const Vector6d delta = gain * innovation;
  pose_.translation() += delta.head<3>();
  const double angle = delta.tail<3>().norm();
  if (angle > 0.0) {
    pose_.linear() = Eigen::AngleAxisd(angle, delta.tail<3>() / angle).toRotationMatrix() *
                     pose_.linear();
  }
  const Matrix6d updated = (Matrix6d::Identity() - gain) * covariance_;
  covariance_ = 0.5 * (updated + updated.transpose());
  return pose_;
}

}  // namespace cube_scan_matcher
