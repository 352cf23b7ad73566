#include "cube_scan_matcher/core/compass_search.h"

#include <stdexcept>
#include <string>

namespace cube_scan_matcher {

void validate(const CompassSettings& s) {
  if (!((s.initial_step.array() > 0.0).all() && s.initial_step.allFinite()))
    throw std::invalid_argument("compass initial_step must all be finite and > 0");
  if (s.levels < 1 || s.levels > 30)
    throw std::invalid_argument("compass levels must be in [1, 30], got " + std::to_string(s.levels));
  if (s.max_evaluations < 1 || s.max_evaluations > 10000000)
    throw std::invalid_argument("compass max_evaluations must be in [1, 1e7], got " +
                                std::to_string(s.max_evaluations));
}

CompassResult compassMaximize(const Objective6& f,
                              const Vector6d& initial, const CompassSettings& s) {
  validate(s);
  CompassResult r;
  r.best = initial;
  r.best_value = r.initial_value = f(initial);
  r.evaluations = 1;
  constexpr int kDirections = 12;  // -step, +step along each of the 6 parameters
  Vector6d step = s.initial_step;
  for (int level = 0; level < s.levels; ++level, step *= 0.5) {
    // The 12 directions are polled in a cycle and the level ends after 12 failures in a row:
    // every point around the current best has then been polled. The point the last move came
    // from is a known failure (its value is below the best) and is not evaluated again. The
    // same moves as restarting the poll at direction 0 after each pass, without re-polling the
    // directions that already failed around the same best.
    int failures = 0;
    int back = -1;  // the direction leading back to the point the last move left
    for (int d = 0; failures < kDirections; d = (d + 1) % kDirections) {
      if (d == back) {
        ++failures;
        continue;
      }
      if (r.evaluations >= s.max_evaluations) return r;
      const int k = d / 2;
      Vector6d q = r.best;
      q[k] += (d % 2 ? 1.0 : -1.0) * step[k];
      const double v = f(q);
      ++r.evaluations;
      if (v > r.best_value) {
        r.best = q;
        r.best_value = v;
        ++r.moves;
        failures = 0;
        back = d ^ 1;
      } else {
        ++failures;
      }
    }
  }
  return r;
}

}  // namespace cube_scan_matcher
