#include "cube_scan_matcher/core/pose.h"

#include <algorithm>
#include <cmath>

namespace cube_scan_matcher {

Eigen::Matrix3d rotationFromRpy(double roll, double pitch, double yaw) {
  // Paper eq. (2) with α = roll, β = pitch, γ = yaw. NB: the preprint's matrix prints the yaw
  // (Cγ, Sγ) and roll (Cα, Sα) symbols swapped relative to its own text; the matrix below is
  // the one that equals Rz(yaw) Ry(pitch) Rx(roll), which the tests check against Eigen.
  const double ca = std::cos(roll), sa = std::sin(roll);
  const double cb = std::cos(pitch), sb = std::sin(pitch);
  const double cg = std::cos(yaw), sg = std::sin(yaw);
  Eigen::Matrix3d r;
  r << cg * cb, cg * sb * sa - sg * ca, sg * sa + cg * sb * ca,  //
      sg * cb, cg * ca + sg * sb * sa, sg * sb * ca - cg * sa,   //
      -sb, cb * sa, cb * ca;
  return r;
}

Eigen::Isometry3d poseToIsometry(const Pose6& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotationFromRpy(pose[3], pose[4], pose[5]);
  t.translation() = pose.head<3>();
  return t;
}

Pose6 isometryToPose(const Eigen::Isometry3d& transform) {
  const Eigen::Matrix3d& r = transform.linear();
  Pose6 pose;
  pose.head<3>() = transform.translation();
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double roll = 0.0;
  double yaw = 0.0;
  if (std::abs(r(2, 0)) < 1.0 - 1e-12) {
    roll = std::atan2(r(2, 1), r(2, 2));
    yaw = std::atan2(r(1, 0), r(0, 0));
  } else {
    // Gimbal lock: only yaw - sign(pitch) * roll is defined; put it all in yaw.
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
  pose[3] = roll;
  pose[4] = pitch;
  pose[5] = yaw;
  return pose;
}

bool isRigid(const Eigen::Isometry3d& transform, double tolerance) {
  if (!transform.matrix().allFinite()) return false;
  const Eigen::Matrix3d& r = transform.linear();
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tolerance &&
         std::abs(r.determinant() - 1.0) <= tolerance;
}

double wrapAngle(double angle) {
  angle = std::remainder(angle, 2.0 * M_PI);
  return angle <= -M_PI ? angle + 2.0 * M_PI : angle;
}

bool posesWithin(const Pose6& a, const Pose6& b, double translation_m, double rotation_rad) {
  if ((a.head<3>() - b.head<3>()).norm() > translation_m) return false;
  for (int i = 3; i < 6; ++i) {
    if (std::abs(wrapAngle(a[i] - b[i])) > rotation_rad) return false;
  }
  return true;
}

}  // namespace cube_scan_matcher
