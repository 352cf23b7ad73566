// The package's default settings: one place, used by the tools, the nodelet and the docs.
#pragma once

#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// Default mode (beyond the paper, measured in BENCHMARK.md); RegistrationSettings::paper()
/// keeps the paper's fixed mode.
/// Coarse stage at E = 0.5 m on the scan collapsed to one point per E/4 voxel: four
/// independent paper GNMM searches (15 vertices, 300 iterations, +-1 m/+-8 deg), two at a time
/// on two threads; the highest J wins. Refine stage: compass search (0.125 m / 1 deg steps, halved 5 times, rotations about
/// the scan centroid) from the two best distinct coarse results, one per thread, on a
/// multi-scale objective: the sum of J over three grids of E/2 cubes shifted by 1/3 of a fine
/// cube, plus 3 x J on the E grid, on the same E/4-collapsed scan. Working copies of grids up
/// to 2^22 cubes use a byte per cube. Measured choices: BENCHMARK.md.
inline RegistrationSettings defaultSettings() {
  RegistrationSettings s = RegistrationSettings::paper(0.5);
  s.collapse_fraction = 0.25;
  s.search.starts = 4;
  s.gnmm.max_iterations = 300;
  s.search.threads = 2;

  s.refine.enabled = true;
  s.refine.edge_fraction = 0.5;
  s.refine.grids = 3;
  s.refine.collapse_fraction = 0.25;
  s.refine.candidates = 2;
  s.refine.coarse_weight = 3.0;
  return s;
}

}  // namespace cube_scan_matcher
