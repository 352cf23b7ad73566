// Beyond the paper: the refine stage. A compass search climbs the multi-scale objective
// (multi_scale_objective.h) from the best distinct results of the coarse stage, one candidate
// per thread; the highest objective wins. The coarse cubes give the wide basin of convergence,
// the fine cubes the accuracy.
#pragma once

#include <vector>

#include "cube_scan_matcher/core/compass_search.h"
#include "cube_scan_matcher/core/multi_scale_objective.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

struct RefineSettings {
  bool enabled = true;         ///< off in the paper's mode.
  double edge_fraction = 0.5;  ///< fine edge = edge_fraction * E, in (0, 1).
  /// Fine grids with origins shifted by k/grids of a fine cube, k = 0..grids-1; the refine
  /// objective is the sum of their J (anti-aliasing). In [1, 8].
  int grids = 3;
  /// Weight w of J on the coarse grid (edge E) added to the fine grids' sum; 0 = fine grids
  /// only. In [0, 100].
  double coarse_weight = 3.0;
  /// Distinct coarse results (of the independent starts, by decreasing J) refined, one per
  /// thread; the highest refine objective wins. In [1, 64].
  int candidates = 2;
  /// Two coarse results are one candidate when their translations differ by at most
  /// distinct_translation [m] and each angle by at most distinct_rotation [rad]; both > 0.
  double distinct_translation = 0.1;
  double distinct_rotation = 0.017453292519943295;  // 1 deg
  /// The refine stage evaluates the scan collapsed to one point per voxel of this * E (the
  /// coarse stage uses RegistrationSettings::collapse_fraction). 0 = all points. In [0, 1].
  double collapse_fraction = 0.25;
  /// Compass search (its rotations pivot about the centroid of the scan points): first steps
  /// 0.125 m / 1 deg, 4 step sizes (halved 3 times, last 15.6 mm / 0.125 deg; the polish
  /// takes it from there).
  CompassSettings compass;
};

/// Throws std::invalid_argument naming the bad setting (only when enabled).
void validate(const RefineSettings& settings);

/// The indices in `ranked` (best first) of its poses that differ from every one kept before
/// them by more than `translation` [m] or, in some angle, `rotation` [rad], up to `count` in
/// all; `kept` (indices already kept) is returned first and counts.
std::vector<int> distinctIndices(const std::vector<Pose6>& ranked, double translation,
                                 double rotation, int count, std::vector<int> kept = {});
struct RefineResult {
  Pose6 pose = Pose6::Zero();  ///< the winner [m, rad] (eq. 2).
  double value = 0.0;          ///< its multi-scale objective.
  int evaluations = 0;         ///< of all candidates.
  int index = 0;               ///< the winner's index in the candidates.
};

/// Compass search from each candidate (at least one), on up to `threads` threads, each with
/// objectives[thread]; the highest value wins (ties: the earlier candidate). A single
/// candidate with threads >= 2 and two objectives is searched on both threads
/// (compassMaximizePaired: the same result). Needs objectives.size() >= min(threads,
/// candidates.size()).
RefineResult refineCandidates(std::vector<MultiScaleObjective>& objectives,
                              const std::vector<Pose6>& candidates,
                              const CompassSettings& compass, int threads);

}  // namespace cube_scan_matcher
