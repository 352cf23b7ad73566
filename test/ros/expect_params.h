// Test helper: two dynamic_reconfigure configs hold the same live parameters.
#pragma once

#include <gtest/gtest.h>

#include "cube_scan_matcher/ScanMatcherConfig.h"

namespace cube_scan_matcher {

inline void expectSameLiveParams(const ScanMatcherConfig& a, const ScanMatcherConfig& b) {
  EXPECT_DOUBLE_EQ(a.cube_edge, b.cube_edge);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_NEAR(a.bounds_translation, b.bounds_translation, 1e-12);
  EXPECT_NEAR(a.bounds_rotation, b.bounds_rotation, 1e-9);
  EXPECT_EQ(a.starts, b.starts);
  EXPECT_EQ(a.threads, b.threads);
  EXPECT_DOUBLE_EQ(a.collapse_fraction, b.collapse_fraction);
  EXPECT_EQ(a.refine, b.refine);
  EXPECT_DOUBLE_EQ(a.refine_edge_fraction, b.refine_edge_fraction);
  EXPECT_EQ(a.refine_grids, b.refine_grids);
  EXPECT_EQ(a.refine_candidates, b.refine_candidates);
  EXPECT_DOUBLE_EQ(a.refine_coarse_weight, b.refine_coarse_weight);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_DOUBLE_EQ(a.min_overlap, b.min_overlap);
  EXPECT_EQ(a.min_j_gain, b.min_j_gain);
  EXPECT_NEAR(a.max_correction_translation, b.max_correction_translation, 1e-12);
  EXPECT_NEAR(a.max_correction_rotation, b.max_correction_rotation, 1e-9);
  EXPECT_EQ(a.max_consecutive_rejections, b.max_consecutive_rejections);
}

}  // namespace cube_scan_matcher
