// Compass (pattern) search: a deterministic local maximiser of any function of a 6-vector.
// Beyond the paper: the refine stage uses it to climb the fine-cube objective from the coarse
// result, where GNMM's random population rarely beats its best vertex in a small box.
#pragma once

#include "cube_scan_matcher/core/vector6.h"

namespace cube_scan_matcher {

struct CompassSettings {
  /// First step per parameter, all > 0. For poses [m, m, m, rad, rad, rad].
  Vector6d initial_step = (Vector6d() << 0.125, 0.125, 0.125, 0.017453292519943295,
                           0.017453292519943295, 0.017453292519943295).finished();
  /// Step sizes tried, in [1, 30]: the first step, then levels - 1 halvings (last step =
  /// initial / 2^(levels-1)).
  int levels = 4;
  int max_evaluations = 2000;     ///< hard budget, in [1, 1e7].
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const CompassSettings& settings);

struct CompassResult {
  Vector6d best = Vector6d::Zero();
  double best_value = 0.0;
  double initial_value = 0.0;
  int evaluations = 0;
  int moves = 0;  ///< accepted steps
  /// compassMaximizePaired: points evaluated ahead that a move made useless (not counted in
  /// evaluations).
  int speculated = 0;
};

/// At each level, try -step and +step along each of the 6 axes in turn from the current point,
/// move to any strictly better point at once, and go on around the axes until no axis
/// improves; then halve the steps. No point is evaluated twice around the same best (and the
/// point a move left is not evaluated again), so a level ends after 12 failures in a row.
CompassResult compassMaximize(const Objective6& f,
                              const Vector6d& initial, const CompassSettings& settings);

/// The same search on two threads: while f0 evaluates the point the poll proposes (on the
/// calling thread), f1 evaluates the point it proposes next if that one fails (on a second
/// thread). f0 and f1 must be the same function (each with its own working memory). Most
/// polls fail (a level ends after 12 failures in a row), so most pairs are both used; after a
/// move the second is dropped (CompassResult::speculated). The moves, the result and the
/// evaluations counted are compassMaximize's, bit for bit.
CompassResult compassMaximizePaired(const Objective6& f0, const Objective6& f1,
                                    const Vector6d& initial, const CompassSettings& settings);

}  // namespace cube_scan_matcher
