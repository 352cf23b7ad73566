// The defaults of cfg/ScanMatcher.cfg (dynamic_reconfigure) must equal the C++ defaults
// (core/defaults.h via NodeParams), so the cfg, the YAML, the README and the code agree.
#include <gtest/gtest.h>

#include "cube_scan_matcher/ros/params.h"

using namespace cube_scan_matcher;

TEST(Params, ReconfigureDefaultsEqualTheCoreDefaults) {
  const ScanMatcherConfig cfg = ScanMatcherConfig::__getDefault__();
  const ScanMatcherConfig code = toConfig(NodeParams{});
  EXPECT_DOUBLE_EQ(cfg.cube_edge, code.cube_edge);
  EXPECT_EQ(cfg.vertices, code.vertices);
  EXPECT_EQ(cfg.iterations, code.iterations);
  EXPECT_NEAR(cfg.bounds_translation, code.bounds_translation, 1e-12);
  EXPECT_NEAR(cfg.bounds_rotation, code.bounds_rotation, 1e-9);
  EXPECT_EQ(cfg.starts, code.starts);
  EXPECT_EQ(cfg.threads, code.threads);
  EXPECT_DOUBLE_EQ(cfg.collapse_fraction, code.collapse_fraction);
  EXPECT_EQ(cfg.refine, code.refine);
  EXPECT_DOUBLE_EQ(cfg.refine_edge_fraction, code.refine_edge_fraction);
  EXPECT_EQ(cfg.refine_grids, code.refine_grids);
  EXPECT_EQ(cfg.seed, code.seed);
  EXPECT_DOUBLE_EQ(cfg.min_overlap, code.min_overlap);
  EXPECT_EQ(cfg.min_j_gain, code.min_j_gain);
  EXPECT_NEAR(cfg.max_correction_translation, code.max_correction_translation, 1e-12);
  EXPECT_NEAR(cfg.max_correction_rotation, code.max_correction_rotation, 1e-9);
  EXPECT_EQ(cfg.max_consecutive_rejections, code.max_consecutive_rejections);
}

TEST(Params, AnInvalidCombinationIsRefusedAndLeavesTheParamsUnchanged) {
  NodeParams p;
  ScanMatcherConfig c = toConfig(p);
  c.refine_edge_fraction = 1.5;  // outside (0, 1)
  EXPECT_THROW(applyConfig(c, p), ParamError);
  EXPECT_DOUBLE_EQ(p.matcher.registration.refine.edge_fraction, 0.5);
  c = toConfig(p);
  c.cube_edge = 0.3;
  applyConfig(c, p);
  EXPECT_DOUBLE_EQ(p.matcher.registration.grid.cube_edge, 0.3);
}
