#include "cube_scan_matcher/core/coarse_search.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <stdexcept>

#include "cube_scan_matcher/core/parallel.h"
#include "require_in_range.h"

namespace cube_scan_matcher {

void validate(const SearchSettings& s) {
  requireInRange("search starts", s.starts, 1, 64);
  requireInRange("search threads", s.threads, 1, 64);
  requireInRange("search retries", s.retries, 0, 8);
  requireInRange("search axis_probe_m", s.axis_probe_m, 0.0, 5.0);
  requireInRange("search axis_probe_gain", s.axis_probe_gain, 0.0, 1.0);
  requireInRange("search ambiguous_weak_ratio", s.ambiguous_weak_ratio, 0.0, 1.0);
  requireInRange("search ambiguous_max_agreeing", s.ambiguous_max_agreeing, 0, 64);
  validate(s.grid);
}

CoarseSearchResult coarseSearch(const std::vector<CoincidenceObjective*>& objectives,
                                const GnmmSettings& gnmm, const SearchSettings& search,
                                const Pose6& guess, const std::vector<Pose6>& seeds,
                                const PointArray* screen) {
  if (int(objectives.size()) < std::min(search.threads, search.starts)) {
    throw std::invalid_argument("coarseSearch: fewer objectives than threads");
  }
  std::vector<GnmmResult> runs(std::size_t(search.starts));
  runOnThreads(search.starts, search.threads, [&](int k, int t) {
    CoincidenceObjective& f = *objectives[std::size_t(t)];
    GnmmSettings gs = gnmm;
    gs.seed += std::uint64_t(k);
    const bool seeded = k >= 1 && std::size_t(k - 1) < seeds.size();
    const Pose6& from = seeded ? seeds[std::size_t(k - 1)] : guess;
    if (!screen || gs.screen_iterations <= 0) {
      runs[std::size_t(k)] =
          Gnmm(gs).maximize([&f](const Vector6d& p) { return double(f(p)); }, from);
      return;
    }
    const PointArray* all = f.scan();
    const Objective6 on_screen = [&f, screen](const Vector6d& p) {
      if (f.scan() != screen) f.setScan(*screen);
      return double(f(p));
    };
    const Objective6 on_all = [&f, all](const Vector6d& p) {
      if (f.scan() != all) f.setScan(*all);
      return double(f(p));
    };
    runs[std::size_t(k)] = Gnmm(gs).maximize(on_screen, on_all, from);
    f.setScan(*all);
  });

  CoarseSearchResult res;
  res.J_guess = int(runs[0].initial_value);
  for (const GnmmResult& r : runs) {
    res.evaluations += r.evaluations;
    res.iterations += r.iterations;
    res.restarts += r.restarts;
  }
  std::vector<std::size_t> order(runs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return runs[a].best_value > runs[b].best_value;
  });
  res.runs.reserve(runs.size());
  for (std::size_t k : order) res.runs.push_back(std::move(runs[k]));
  return res;
}

}  // namespace cube_scan_matcher
