// The paper's registration errors (section 3.3, eqs. 7-8), used by the benchmark, the demo's
// evaluator and the tests.
#pragma once

#include <Eigen/Geometry>

namespace cube_scan_matcher {

/// Errors of eqs. (7)-(8) between an estimate and a reference pose (both of eq. 2).
struct PoseError {
  double es_m;    ///< Es, eq. (7): Euclidean distance of the translations [m].
  double ea_deg;  ///< Ea, eq. (8): root of the summed squared roll, pitch, yaw differences
                  ///< (each wrapped to (-180, 180]) [deg].
};
PoseError poseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& reference);

}  // namespace cube_scan_matcher
