#include "cube_scan_matcher/core/refine_search.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cube_scan_matcher/core/parallel.h"
#include "require_in_range.h"

namespace cube_scan_matcher {

void validate(const RefineSettings& s) {
  if (!s.enabled) return;
  if (!(s.edge_fraction > 0.0 && s.edge_fraction < 1.0)) {
    throw std::invalid_argument("refine edge_fraction must be in (0, 1), got " +
                                std::to_string(s.edge_fraction));
  }
  validate(s.compass);
  requireInRange("refine coarse_weight", s.coarse_weight, 0.0, 100.0);
  requireInRange("refine candidates", s.candidates, 1, 64);
  requireInRange("refine grids", s.grids, 1, 8);
  requireInRange("refine collapse_fraction", s.collapse_fraction, 0.0, 1.0);
  if (!(s.distinct_translation > 0.0 && s.distinct_rotation > 0.0)) {
    throw std::invalid_argument("refine distinct_translation and distinct_rotation must be > 0");
  }
}

std::vector<int> distinctIndices(const std::vector<Pose6>& ranked, double translation,
                                 double rotation, int count, std::vector<int> kept) {
  for (int k = 0; k < int(ranked.size()) && int(kept.size()) < count; ++k) {
    if (std::none_of(kept.begin(), kept.end(), [&](int c) {
          return posesWithin(ranked[std::size_t(k)], ranked[std::size_t(c)], translation,
                             rotation);
        })) {
      kept.push_back(k);
    }
  }
  return kept;
}

RefineResult refineCandidates(std::vector<MultiScaleObjective>& objectives,
                              const std::vector<Pose6>& candidates,
                              const CompassSettings& compass, int threads) {
  if (candidates.empty()) throw std::invalid_argument("refineCandidates: no candidate");
  if (int(objectives.size()) < std::min(threads, int(candidates.size()))) {
    throw std::invalid_argument("refineCandidates: fewer objectives than threads");
  }
  std::vector<CompassResult> results(candidates.size());
  if (candidates.size() == 1 && threads >= 2 && objectives.size() >= 2) {
    // One candidate: its poll on both threads (compassMaximizePaired, the same result).
    MultiScaleObjective &f0 = objectives[0], &f1 = objectives[1];
    results[0] = compassMaximizePaired([&f0](const Vector6d& q) { return f0(q); },
                                       [&f1](const Vector6d& q) { return f1(q); },
                                       f0.variable(candidates[0]), compass);
  } else {
    runOnThreads(int(candidates.size()), threads, [&](int k, int t) {
      MultiScaleObjective& f = objectives[std::size_t(t)];
      results[std::size_t(k)] =
          compassMaximize([&f](const Vector6d& q) { return f(q); },
                          f.variable(candidates[std::size_t(k)]), compass);
    });
  }
  RefineResult best;
  best.value = -1.0;
  for (std::size_t k = 0; k < results.size(); ++k) {
    best.evaluations += results[k].evaluations;
    if (results[k].best_value > best.value) {
      best.value = results[k].best_value;
      best.index = int(k);
      best.pose = objectives[0].pose(results[k].best);
    }
  }
  return best;
}

}  // namespace cube_scan_matcher
