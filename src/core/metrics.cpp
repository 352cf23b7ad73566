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

}  // namespace cube_scan_matcher
