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
  Vector6d step = s.initial_step;
  for (int level = 0; level < s.levels; ++level, step *= 0.5) {
    bool improved = true;
    while (improved) {
      improved = false;
      for (int k = 0; k < 6; ++k) {
        for (const double sign : {-1.0, 1.0}) {
          if (r.evaluations >= s.max_evaluations) return r;
          Vector6d q = r.best;
          q[k] += sign * step[k];
          const double v = f(q);
          ++r.evaluations;
          if (v > r.best_value) {
            r.best = q;
            r.best_value = v;
            ++r.moves;
            improved = true;
          }
        }
      }
    }
  }
  return r;
}

}  // namespace cube_scan_matcher
