// Range and finiteness filters: what is dropped, and settings refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/core/filters.h"

using namespace cube_scan_matcher;

TEST(Filters, DropsNonFiniteAndOutOfRange) {
  PointArray in;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  in.push_back(1, 0, 0);
  in.push_back(nan, 0, 0);
  in.push_back(0, inf, 0);
  in.push_back(0.1f, 0, 0);  // too close
  in.push_back(90, 0, 0);    // too far
  in.push_back(0, 0, 50);
  RangeFilterSettings s;
  s.min_range = 0.5;
  s.max_range = 81;
  FilterStats st;
  const PointArray out = filterPoints(in, s, &st);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(st.non_finite, 2u);
  EXPECT_EQ(st.out_of_range, 2u);
  EXPECT_EQ(st.kept, 2u);
  EXPECT_FLOAT_EQ(out.z[1], 50.f);
  // The kept indices name the same points; with times, a point without a finite time goes too.
  FilterStats kst;
  EXPECT_EQ(keptIndices(in, {}, s, &kst), (std::vector<std::uint32_t>{0, 5}));
  EXPECT_EQ(kst.kept, 2u);
  EXPECT_EQ(kst.non_finite, 2u);
  const std::vector<float> times{-0.1f, 0, 0, 0, 0, nan};
  EXPECT_EQ(keptIndices(in, times, s, &kst), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(kst.non_finite, 3u);
  std::vector<float> times_out;
  EXPECT_EQ(filterPoints(in, times, s, times_out).size(), 1u);
  EXPECT_THROW(keptIndices(in, {0.0f}, s), std::invalid_argument);
}

TEST(Filters, RangeIsMeasuredFromTheOrigin) {
  PointArray in;
  in.push_back(10, 0, 0);
  RangeFilterSettings s;
  s.max_range = 5;
  s.origin = Eigen::Vector3d(8, 0, 0);
  EXPECT_EQ(filterPoints(in, s).size(), 1u);
}

TEST(Filters, InvalidSettingsAreRefusedByName) {
  RangeFilterSettings s;
  s.min_range = -1;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.min_range = 5;
  s.max_range = 2;
  try {
    validate(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_range"), std::string::npos);
  }
}
