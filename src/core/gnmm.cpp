#include "cube_scan_matcher/core/gnmm.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace cube_scan_matcher {

void validate(const GnmmSettings& s) {
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  if (s.vertices < 7 || s.vertices > 1000)
    fail("vertices must be in [7, 1000] (a 6-D simplex needs 7), got " + std::to_string(s.vertices));
  if (s.max_iterations < 1 || s.max_iterations > 1000000)
    fail("max_iterations must be in [1, 1000000], got " + std::to_string(s.max_iterations));
  if (!((s.bounds.array() > 0.0).all() && s.bounds.allFinite()))
    fail("restart bounds must all be finite and > 0");
  if (s.screen_iterations < 0 || s.screen_iterations > s.max_iterations)
    fail("screen_iterations must be in [0, max_iterations = " + std::to_string(s.max_iterations) +
         "], got " + std::to_string(s.screen_iterations));
  if (!(s.reflection > 0.0)) fail("reflection must be > 0");
  if (!(s.expansion > 1.0)) fail("expansion must be > 1");
  if (!(s.contraction > 0.0 && s.contraction < 1.0)) fail("contraction must be in (0, 1)");
}

Gnmm::Gnmm(const GnmmSettings& settings) : settings_(settings) { validate(settings_); }

GnmmResult Gnmm::maximize(const Objective6& f, const Vector6d& initial) const {
  return maximize(f, f, initial);
}

GnmmResult Gnmm::maximize(const Objective6& screen, const Objective6& full,
                          const Vector6d& initial) const {
  const GnmmSettings& s = settings_;
  const bool screening = &screen != &full && s.screen_iterations > 0;
  const Objective6* f = screening ? &screen : &full;
  const int n = s.vertices;
  std::mt19937_64 rng(s.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  GnmmResult r;
  auto eval = [&](const Vector6d& x) {
    ++r.evaluations;
    return (*f)(x);
  };
  auto draw = [&](const Vector6d& center, const Vector6d& half) {
    Vector6d x;
    for (int k = 0; k < 6; ++k) x[k] = center[k] + half[k] * unit(rng);
    return x;
  };

  std::vector<Vector6d> x(n);
  std::vector<double> fx(n);
  x[0] = initial;
  fx[0] = eval(initial);
  r.initial_value = fx[0];
  if (screening) {  // J at the guess on the objective itself (J_guess, for the gate)
    ++r.evaluations;
    r.initial_value = full(initial);
  }
  for (int i = 1; i < n; ++i) {
    x[i] = draw(initial, s.bounds);
    fx[i] = eval(x[i]);
  }
  for (r.iterations = 0; r.iterations < s.max_iterations;) {
    if (screening && r.iterations == s.screen_iterations) {
      f = &full;
      for (int i = 0; i < n; ++i) fx[i] = eval(x[i]);
    }
    ++r.iterations;
    // Worst (lowest f), second worst and best vertex.
    int worst = 0, best = 0;
    for (int i = 1; i < n; ++i) {
      if (fx[i] < fx[worst]) worst = i;
      if (fx[i] > fx[best]) best = i;
    }
    int second = worst == 0 ? 1 : 0;
    for (int i = 0; i < n; ++i) {
      if (i != worst && fx[i] < fx[second]) second = i;
    }
    // Centroid of all vertices but the worst.
    Vector6d c = Vector6d::Zero();
    for (int i = 0; i < n; ++i) {
      if (i != worst) c += x[i];
    }
    c /= double(n - 1);

    const Vector6d xr = c + s.reflection * (c - x[worst]);
    const double fr = eval(xr);
    if (fr > fx[best]) {
      const Vector6d xe = c + s.expansion * (xr - c);
      const double fe = eval(xe);
      if (fe > fr) {
        x[worst] = xe;
        fx[worst] = fe;
      } else {
        x[worst] = xr;
        fx[worst] = fr;
      }
    } else if (fr > fx[second]) {
      x[worst] = xr;
      fx[worst] = fr;
    } else {
      // Outside contraction if the reflection beat the worst vertex, inside otherwise.
      const bool outside = fr > fx[worst];
      const Vector6d xc = outside ? Vector6d(c + s.contraction * (xr - c))
                                  : Vector6d(c + s.contraction * (x[worst] - c));
      const double fc = eval(xc);
      if (fc > std::max(fr, fx[worst])) {
        x[worst] = xc;
        fx[worst] = fc;
      } else {
        // Where Nelder-Mead would shrink towards the best vertex, GNMM keeps the best vertex
        // and restarts all others at random around the initial estimate.
        ++r.restarts;
        for (int i = 0; i < n; ++i) {
          if (i == best) continue;
          x[i] = draw(initial, s.bounds);
          fx[i] = eval(x[i]);
        }
      }
    }
  }
  if (f != &full) {  // every iteration screened: the population on the objective itself
    f = &full;
    for (int i = 0; i < n; ++i) fx[i] = eval(x[i]);
  }
  const int best = int(std::max_element(fx.begin(), fx.end()) - fx.begin());
  r.best = x[best];
  r.best_value = fx[best];
  return r;
}

}  // namespace cube_scan_matcher
