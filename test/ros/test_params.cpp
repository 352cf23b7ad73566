// The defaults of cfg/ScanMatcher.cfg (dynamic_reconfigure) must equal the C++ defaults
// (RegistrationSettings{} via NodeParams), so the cfg, the YAML, the README and the code agree.
#include <gtest/gtest.h>

#include "cube_scan_matcher/ros/params.h"
#include "expect_params.h"

using namespace cube_scan_matcher;

TEST(Params, ReconfigureDefaultsEqualTheCoreDefaults) {
  expectSameLiveParams(ScanMatcherConfig::__getDefault__(), toConfig(NodeParams{}));
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
