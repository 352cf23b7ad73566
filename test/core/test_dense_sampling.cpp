// keepDenselySampled: the points of cubes holding at least min_points points survive, in order.
#include <gtest/gtest.h>

#include <stdexcept>

#include "cube_scan_matcher/core/dense_sampling.h"

using namespace cube_scan_matcher;

TEST(DenseSampling, KeepsThePointsOfWellFilledCubesInOrder) {
  PointArray in;
  in.push_back(5.2f, 0.1f, 0.1f);                                    // alone in its 0.5 m cube
  for (int i = 0; i < 4; ++i) in.push_back(0.1f * i, 0.1f, 0.1f);    // 4 in cube (0, 0, 0)
  in.push_back(-0.1f, 0.1f, 0.1f);                                   // 1 in cube (-1, 0, 0)
  for (int i = 0; i < 3; ++i) in.push_back(1.1f, 0.1f * i, -0.2f);   // 3 in cube (2, 0, -1)
  DenseSamplingStats stats;
  const PointArray out = keepDenselySampled(in, 0.5, 3, &stats);
  ASSERT_EQ(out.size(), 7u);
  EXPECT_FLOAT_EQ(out.x[0], 0.0f);   // the first kept point is the first of cube (0, 0, 0)
  EXPECT_FLOAT_EQ(out.x[4], 1.1f);
  EXPECT_EQ(stats.cubes, 4u);
  EXPECT_EQ(stats.dense_cubes, 2u);
  EXPECT_EQ(stats.kept, 7u);
  EXPECT_EQ(keepDenselySampled(in, 0.5, 1).size(), in.size());   // 1 = every point
  EXPECT_EQ(keepDenselySampled(in, 0.5, 5).size(), 0u);
  EXPECT_EQ(keepDenselySampled(PointArray(), 0.5, 3).size(), 0u);
}

TEST(DenseSampling, RejectsBadArguments) {
  PointArray in;
  in.push_back(0.f, 0.f, 0.f);
  EXPECT_THROW(keepDenselySampled(in, 0.0, 3), std::invalid_argument);
  EXPECT_THROW(keepDenselySampled(in, 0.5, 0), std::invalid_argument);
}
