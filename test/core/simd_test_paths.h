// The vector paths a test compares with each other: every path this CPU supports. A path it
// cannot run (AVX-512 on most desktops, both on ARM) is named on stdout and in the test's XML
// record, so a run there says which paths it did not check instead of passing silently.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/simd_path.h"

namespace cube_scan_matcher {

inline std::vector<SimdPath> simdPathsToCompare() {
  std::string skipped;
  for (const SimdPath p : {SimdPath::Avx512, SimdPath::Avx2, SimdPath::Portable}) {
    if (simdPathSupported(p)) continue;
    skipped += (skipped.empty() ? "" : " ") + std::string(simdPathName(p));
  }
  if (!skipped.empty()) {
    std::printf("[  SKIPPED ] vector paths this CPU cannot run, not compared: %s\n",
                skipped.c_str());
    ::testing::Test::RecordProperty("simd_paths_skipped", skipped);
  }
  return supportedSimdPaths();
}

}  // namespace cube_scan_matcher
