#include "cube_scan_matcher/core/metrics.h"

#include <algorithm>
#include <cmath>

#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

PoseError poseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& reference) {
  const Pose6 a = isometryToPose(estimate);
  const Pose6 b = isometryToPose(reference);
  double sum = 0.0;
  for (int k = 3; k < 6; ++k) {
    const double d = wrapAngle(a[k] - b[k]);
    sum += d * d;
  }
  return {(a.head<3>() - b.head<3>()).norm(), rad2deg(std::sqrt(sum))};
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, std::size_t(q * double(values.size())))];
}

Repeatability repeatability(const std::vector<Eigen::Isometry3d>& estimates) {
  Repeatability r;
  if (estimates.empty()) return r;
  const Eigen::Matrix3d R0 = estimates.front().linear();
  Eigen::Vector3d t_med, w_med;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> t, w;
    for (const Eigen::Isometry3d& e : estimates) {
      const Eigen::AngleAxisd d(e.linear() * R0.transpose());
      t.push_back(e.translation()(k));
      w.push_back((d.angle() * d.axis())(k));
    }
    t_med(k) = quantile(t, 0.5);
    w_med(k) = quantile(w, 0.5);
  }
  const Eigen::Matrix3d R_med =
      (w_med.norm() > 0.0 ? Eigen::AngleAxisd(w_med.norm(), w_med.normalized()).toRotationMatrix()
                          : Eigen::Matrix3d::Identity()) *
      R0;
  std::vector<double> dm, dd;
  for (const Eigen::Isometry3d& e : estimates) {
    dm.push_back((e.translation() - t_med).norm());
    dd.push_back(rad2deg(Eigen::AngleAxisd(e.linear() * R_med.transpose()).angle()));
  }
  r.median_m = quantile(dm, 0.5);
  r.median_deg = quantile(dd, 0.5);
  return r;
}

}  // namespace cube_scan_matcher
