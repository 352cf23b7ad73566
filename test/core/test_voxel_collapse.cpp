// collapseToVoxels: one point per voxel, the first one kept.
#include <gtest/gtest.h>

#include <stdexcept>

#include "cube_scan_matcher/core/voxel_collapse.h"

using namespace cube_scan_matcher;

TEST(VoxelCollapse, KeepsOnePointPerVoxel) {
  PointArray in;
  for (int i = 0; i < 10; ++i) in.push_back(0.01f * i, 0.01f, 0.01f);  // one 0.25 m voxel
  in.push_back(1.1f, 0.1f, 0.1f);
  in.push_back(-0.1f, 0.1f, 0.1f);  // negative side is another voxel
  const PointArray out = collapseToVoxels(in, 0.25);
  EXPECT_EQ(out.size(), 3u);
  EXPECT_FLOAT_EQ(out.x[0], 0.f);  // the first point of a voxel is kept
  EXPECT_THROW(collapseToVoxels(in, 0.0), std::invalid_argument);
}
