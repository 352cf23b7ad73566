// The package's default settings: one place, used by the tools, the nodelet and the docs.
#pragma once

#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// Default mode (beyond the paper, measured in BENCHMARK.md); RegistrationSettings::paper()
/// keeps the paper's fixed mode.
/// Coarse stage at E = 0.5 m on the scan collapsed to one point per E/2 voxel: up to four
/// independent paper GNMM searches (15 vertices, 500 iterations, +-1 m/+-8 deg), two at a time
/// on two threads, stopping after a round in which two agree (0.1 m, 1 deg); the highest J
/// wins. Polish runs are available but off (5 ms per 100 iterations, no
/// gain in success once the refine stage climbs). Refine stage: compass search (0.125 m / 1 deg
/// steps, halved 5 times) on the sum of J over three grids of E/2 cubes shifted by 1/3 of a
/// fine cube, on the scan collapsed to one point per E/4 voxel. Measured choices: BENCHMARK.md, "Default mode".
inline RegistrationSettings defaultSettings() {
  RegistrationSettings s = RegistrationSettings::paper(0.5);
  s.collapse_fraction = 0.25;
  s.search.starts = 4;
  s.search.threads = 2;
  s.search.consensus = 0;
  s.search.polish_runs = 0;
  s.search.polish_iterations = 100;

  s.refine.enabled = true;
  s.refine.edge_fraction = 0.5;
  s.refine.grids = 3;
  s.refine.collapse_fraction = 0.25;
  s.refine.candidates = 2;
  return s;
}

}  // namespace cube_scan_matcher
