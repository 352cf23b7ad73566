// Beyond the paper: a grid search of J over the planar motions (x, y, yaw) around a centre, whose
// best local maxima seed the coarse stage's GNMM starts. Without odometry a ground robot may
// have driven on, stopped or turned on the spot since the last scan; a GNMM from one guess
// within a 6-D box wide enough for all three rarely lands on J's narrow peak at the truth (a
// turn of 30 deg peaks within a few degrees), and the grid finds it in every case.
#pragma once

#include <cstdint>
#include <vector>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

/// The grid: centre + (i * step_m, j * step_m, 0, 0, 0, k * step_yaw) for |i * step_m| <=
/// half_width_m and |k * step_yaw| <= half_yaw (z, roll and pitch stay the centre's).
struct PlanarGridSettings {
  double half_width_m = 0.0;  ///< [m] half the grid's extent in x and y; 0 = no grid. In [0, 20].
  double step_m = 0.25;       ///< [m] in [0.05, 5]: at most E/2 so that J's peak is not stepped over.
  double half_yaw = 0.0;      ///< [rad] half the yaw extent, in [0, pi].
  double step_yaw = 0.05235987755982988;  ///< [rad] 3 deg, in [0.1 deg, 45 deg].

  bool enabled() const { return half_width_m > 0.0 || half_yaw > 0.0; }
  /// The number of poses the grid evaluates (64-bit: validate() refuses more than 1e6).
  std::int64_t poses() const;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const PlanarGridSettings& settings);

struct PlanarGridResult {
  /// The grid's local maxima (J above all its up to 26 neighbours', ties broken by the grid
  /// order), best first; at most `count` of them.
  std::vector<Pose6> maxima;
  std::vector<int> maxima_J;
  int evaluations = 0;
};

/// J (each thread's own objective, all bound to the same scan) at every pose of the grid around
/// `centre`, on `threads` threads; the result does not depend on the thread count.
PlanarGridResult planarGridMaxima(const std::vector<CoincidenceObjective*>& objectives,
                                  const PlanarGridSettings& settings, const Pose6& centre,
                                  int count, int threads);

}  // namespace cube_scan_matcher
