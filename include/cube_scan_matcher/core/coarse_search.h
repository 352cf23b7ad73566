// The coarse stage (paper section 2.3, beyond it in the number of starts): independent GNMM
// searches for the maximum of J on the E grid from the initial estimate.
#pragma once

#include <vector>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/gnmm.h"
#include "cube_scan_matcher/core/planar_grid.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

/// Beyond the paper: how the coarse stage spends its evaluations. The paper runs one GNMM
/// from the initial estimate (starts = 1).
struct SearchSettings {
  /// Independent GNMM searches from the initial estimate, seeds gnmm.seed + k; the highest J
  /// wins (ties: lowest k). One GNMM from +-1 m/+-8 deg lands in a wrong local maximum in a
  /// part of the trials, four rarely all do. In [1, 64].
  int starts = 4;
  /// Threads the starts (and the refine candidates, the polish's plane lookups and the grid
  /// builds) run on; each thread takes the next start not yet run and owns a working copy of
  /// every grid (a start's result does not depend on the thread). In [1, 64].
  int threads = 2;
  /// Beyond the paper: when the polished result is not confirmed (the polish found too few
  /// planes or left the basin, or flags it degenerate: the wrong poses the search lands on
  /// from big starts are, a hall slid along its aisle), the search (coarse, refine, polish)
  /// runs again from new seeds (gnmm.seed + starts * attempt + k), up to `retries` more times;
  /// the first confirmed result wins (an ambiguous one only once a retry lands on it again:
  /// ambiguous_weak_ratio), else the first one. No retry without the polish (the
  /// paper's mode) or when the first result is confirmed. A scene that is degenerate
  /// (a tunnel) pays every retry. With the planar grid (`grid`) the seeds do not change
  /// between searches: a result that is not confirmed is first refined and polished again
  /// from each of the first search's other coarse results (those 0.25 m / 2 deg apart from
  /// the tried ones, the one nearest the guess first), then searched again; an ambiguous one
  /// is searched again. In [0, 8].
  int retries = 2;
  /// Beyond the paper: after the polish, J on the E grid is probed along the weakest
  /// translation axis of the result (PolishResult::translation_weak_axis, reference frame) at
  /// +-E/4, +-E/2, ... up to +-axis_probe_m [m] (2 * 4 * axis_probe_m / E evaluations). Where
  /// the scene fixes that axis only weakly (a wall along the track) the search can stop short
  /// of the maximum along it; when the best probe beats the result's J by more than
  /// axis_probe_gain (a fraction of J), the polish runs again from the probe and its result
  /// replaces the first if its J is higher. 0 = off. In [0, 5].
  double axis_probe_m = 1.0;
  /// The probe's J gain that moves the result: J_probe > J * (1 + gain). In [0, 1].
  double axis_probe_gain = 0.03;
  /// Beyond the paper: a confirmed result is ambiguous when its weakest translation axis is
  /// weakly supported (PolishResult::translation_weak_ratio below ambiguous_weak_ratio) and at
  /// most ambiguous_max_agreeing of the starts' coarse results lie near it (the others found
  /// other maxima). It counts only when a retry lands on the same pose (within 5 cm and
  /// 0.5 deg: a consensus); else the result is marked ambiguous (RegistrationResult::ambiguous,
  /// rejected by the gate). 0 = off. In [0, 1] and [0, 64].
  double ambiguous_weak_ratio = 0.03;
  int ambiguous_max_agreeing = 1;
  /// Beyond the paper: before the starts, J on the coarse points over a grid of planar motions
  /// (planar_grid.h) around the guess (or the centre align() is given); start 0 runs from the
  /// guess, start k >= 1 from the grid's k-th best local maximum (from the guess when the grid
  /// has fewer). Off by default (the online matcher turns it on without odometry).
  PlanarGridSettings grid;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const SearchSettings& settings);

struct CoarseSearchResult {
  /// One GNMM result per start, by decreasing J (ties: lowest start first): runs[0] wins.
  std::vector<GnmmResult> runs;
  int J_guess = 0;      ///< J at the initial estimate.
  int evaluations = 0;  ///< summed over the starts.
  int iterations = 0;   ///< summed over the starts.
  int restarts = 0;     ///< summed over the starts.
};

/// Runs search.starts GNMM searches (gnmm settings, seed gnmm.seed + k for start k) from
/// `guess` (start k >= 1 from seeds[k - 1] where there is one: the planar grid's maxima), each
/// taken by the next free thread t with objectives[t] (each thread's own working copy of the E
/// grid, bound to the same scan). Needs objectives.size() >= min(search.threads, search.starts).
/// With `screen` (a subset of the objectives' scan) and gnmm.screen_iterations > 0, each start
/// runs its first screen_iterations on `screen` (Gnmm::maximize with a screening objective);
/// the objectives are bound to their own scan again on return.
CoarseSearchResult coarseSearch(const std::vector<CoincidenceObjective*>& objectives,
                                const GnmmSettings& gnmm, const SearchSettings& search,
                                const Pose6& guess, const std::vector<Pose6>& seeds = {},
                                const PointArray* screen = nullptr);

}  // namespace cube_scan_matcher
