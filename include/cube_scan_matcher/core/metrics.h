// The paper's registration errors (section 3.3, eqs. 7-8), used by the benchmark, the demo's
// evaluator and the tests.
#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace cube_scan_matcher {

/// Errors of eqs. (7)-(8) between an estimate and a reference pose (both of eq. 2).
struct PoseError {
  double es_m;    ///< Es, eq. (7): Euclidean distance of the translations [m].
  double ea_deg;  ///< Ea, eq. (8): root of the summed squared roll, pitch, yaw differences
                  ///< (each wrapped to (-180, 180]) [deg].
  /// The benchmarks' success: Es < 0.10 m and Ea < 1 deg.
  bool success() const { return es_m < 0.10 && ea_deg < 1.0; }
};
PoseError poseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& reference);

/// Repeatability of one pair registered from several starts: the median pose of `estimates`
/// (component-wise median of the translations and of the rotation vectors relative to the
/// first estimate) and the median over estimates of each one's distance to it.
struct Repeatability {
  double median_m = 0.0;    ///< median translation distance to the median pose [m]
  double median_deg = 0.0;  ///< median rotation angle to the median pose [deg]
};
Repeatability repeatability(const std::vector<Eigen::Isometry3d>& estimates);

/// The q-quantile (q in [0, 1]) of `values` as the element at index floor(q n) of the sorted
/// values (the last one for q = 1); 0 for no value. Medians and p95s of the tools' reports.
double quantile(std::vector<double> values, double q);

}  // namespace cube_scan_matcher
