// Globalized Nelder-Mead method (paper section 2.3): a Nelder-Mead search over a population of
// N >= 7 vertices in 6-D that, where plain Nelder-Mead would shrink the simplex, keeps the best
// vertex and restarts all others at random around the initial estimate. It maximises any
// function of a 6-vector and knows nothing about points or cubes.
#pragma once

#include <cstdint>

#include "cube_scan_matcher/core/vector6.h"

namespace cube_scan_matcher {

struct GnmmSettings {
  int vertices = 15;          ///< N, population size, in [7, 1000] (paper: 15).
  /// Nelder-Mead iterations, in [1, 1e6]. The paper runs 500; the package's multi-start
  /// coarse stage runs 300 per start (RegistrationSettings::paper() sets 500).
  int max_iterations = 300;
  /// Restart half-widths around the initial estimate, per parameter, all > 0. For poses:
  /// [m, m, m, rad, rad, rad]; the paper's default is +-1 m, +-8 deg.
  Vector6d bounds = (Vector6d() << 1.0, 1.0, 1.0, 0.13962634015954636, 0.13962634015954636,
                     0.13962634015954636).finished();
  double reflection = 1.0;    ///< alpha > 0.
  double expansion = 2.0;     ///< gamma > 1.
  double contraction = 0.5;   ///< rho in (0, 1).
  std::uint64_t seed = 42;    ///< RNG seed: equal seeds give equal runs.
  /// Iterations (of max_iterations) run on the screening objective first, when maximize() is
  /// given one; the population is then evaluated again on the objective and the rest run on
  /// it. In [0, max_iterations].
  int screen_iterations = 0;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const GnmmSettings& settings);

struct GnmmResult {
  Vector6d best = Vector6d::Zero();
  double best_value = 0.0;
  double initial_value = 0.0;  ///< f at the initial estimate (vertex 0 of the population).
  int evaluations = 0;
  int iterations = 0;
  int restarts = 0;
};

class Gnmm {
 public:
  explicit Gnmm(const GnmmSettings& settings);  // validates

  /// Maximises f starting from `initial`. The population is the initial estimate plus N-1
  /// vertices drawn uniformly within +-bounds around it.
  GnmmResult maximize(const Objective6& f, const Vector6d& initial) const;

  /// The same, with the first screen_iterations run on `screen` (a cheaper approximation of f:
  /// f on a subset of the points); best_value and initial_value are f's.
  GnmmResult maximize(const Objective6& screen, const Objective6& f, const Vector6d& initial) const;

 private:
  GnmmSettings settings_;
};

}  // namespace cube_scan_matcher
