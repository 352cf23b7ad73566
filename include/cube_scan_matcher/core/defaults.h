// The package's default settings: one place, used by the tools, the nodelet and the docs.
#pragma once

#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// Default mode (beyond the paper, measured in BENCHMARK.md); RegistrationSettings::paper()
/// keeps the paper's fixed mode.
/// Coarse stage: the paper's GNMM (15 vertices, 500 iterations, +-1 m/+-8 deg) at E = 0.5 m on
/// the scan collapsed to one point per E/4 voxel. Refine stage: GNMM (300 iterations, stops
/// after 40 without gain) within +-0.3 m/+-3 deg of the coarse result, maximising the sum of J
/// over two grids of E/2 cubes shifted by half a fine cube.
inline RegistrationSettings defaultSettings() {
  RegistrationSettings s = RegistrationSettings::paper(0.5);
  s.collapse_fraction = 0.25;

  s.refine.enabled = true;
  s.refine.edge_fraction = 0.5;
  s.refine.grids = 2;
  s.refine.gnmm.max_iterations = 300;
  s.refine.gnmm.stall_iterations = 40;
  const double a = deg2rad(3.0);
  s.refine.gnmm.bounds << 0.3, 0.3, 0.3, a, a, a;
  return s;
}

}  // namespace cube_scan_matcher
