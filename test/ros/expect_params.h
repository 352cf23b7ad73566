// Test helper: two dynamic_reconfigure configs hold the same live parameters (every parameter
// of cfg/ScanMatcher.cfg, found through the generated descriptions).
#pragma once

#include <cmath>

#include <boost/any.hpp>
#include <gtest/gtest.h>

#include "cube_scan_matcher/ScanMatcherConfig.h"

namespace cube_scan_matcher {

inline void expectSameLiveParams(const ScanMatcherConfig& a, const ScanMatcherConfig& b) {
  for (const auto& d : ScanMatcherConfig::__getParamDescriptions__()) {
    boost::any va, vb;
    d->getValue(a, va);
    d->getValue(b, vb);
    if (d->type == "double") {
      const double x = boost::any_cast<double>(va), y = boost::any_cast<double>(vb);
      EXPECT_NEAR(x, y, 1e-9 * std::max(1.0, std::abs(x))) << d->name;
    } else if (d->type == "int") {
      EXPECT_EQ(boost::any_cast<int>(va), boost::any_cast<int>(vb)) << d->name;
    } else if (d->type == "bool") {
      EXPECT_EQ(boost::any_cast<bool>(va), boost::any_cast<bool>(vb)) << d->name;
    } else {
      ADD_FAILURE() << d->name << ": unexpected cfg type " << d->type;
    }
  }
}

}  // namespace cube_scan_matcher
