// collapseToVoxels: one point per voxel, the first one kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

#include "cube_scan_matcher/core/simd_path.h"
#include "simd_test_paths.h"
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

TEST(VoxelCollapse, NestedVoxelsCollapseFromTheFinerResultToTheSamePoints) {
  EXPECT_TRUE(voxelsNest(0.25, 0.125));   // E/2 and E/4 at E = 0.5
  EXPECT_TRUE(voxelsNest(0.15, 0.075));   // at E = 0.3: not exact decimals, still nested
  EXPECT_TRUE(voxelsNest(0.4, 0.05));     // 2^3
  EXPECT_TRUE(voxelsNest(0.125, 0.125));  // 2^0
  EXPECT_FALSE(voxelsNest(0.25, 0.1));
  EXPECT_FALSE(voxelsNest(0.3, 0.2));
  EXPECT_FALSE(voxelsNest(0.125, 0.25));  // the finer voxel must be the second
  EXPECT_FALSE(voxelsNest(0.0, 0.125));
  // Points on and around voxel boundaries, on both sides of the origin.
  PointArray in;
  for (int i = 0; i < 20000; ++i) {
    const float u = float((i * 7919) % 4001 - 2000) * 0.00371f;
    in.push_back(u, 0.5f * u - 0.075f * float(i % 9), float(i % 13) * 0.0375f - 0.2f);
  }
  for (const double edge : {0.5, 0.3}) {
    const PointArray fine = collapseToVoxels(in, edge / 4);
    const PointArray direct = collapseToVoxels(in, edge / 2);
    const PointArray nested = collapseToVoxels(fine, edge / 2);
    ASSERT_LT(direct.size(), fine.size());
    EXPECT_EQ(direct.x, nested.x) << "E = " << edge;
    EXPECT_EQ(direct.y, nested.y);
    EXPECT_EQ(direct.z, nested.z);
  }
}

TEST(VoxelCollapse, KeepsEveryVoxelWhenThereAreAsManyAsPoints) {
  // Every point in its own voxel: the voxel map starts at an eighth of the points and grows
  // several times; nothing may be lost or merged on the way.
  PointArray in;
  for (int i = 0; i < 60000; ++i) in.push_back(float(i % 50), float((i / 50) % 40), float(i / 2000));
  for (int i = 0; i < 60000; i += 7) in.push_back(float(i % 50) + 0.1f, float((i / 50) % 40), float(i / 2000));
  const PointArray out = collapseToVoxels(in, 0.5);
  ASSERT_EQ(out.size(), 60000u);
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_EQ(out.x[i], in.x[i]);  // the first point of each voxel, in input order
    ASSERT_EQ(out.z[i], in.z[i]);
  }
}

// The voxel keys are computed a block at a time on the active vector path: every path keeps
// the points a plain scalar floor(x / voxel) keeps, across blocks, on voxel boundaries, on
// both sides of the origin and beyond the key range (clamped to its last voxel).
TEST(VoxelCollapse, EveryVectorPathKeepsThePointsOfTheScalarVoxels) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(-30.f, 30.f);
  PointArray in;
  for (int i = 0; i < 5000; ++i) in.push_back(u(rng), u(rng), 0.1f * u(rng));
  for (int i = -40; i <= 40; ++i) {
    in.push_back(0.125f * float(i), -0.125f * float(i), 0.f);  // on boundaries
    in.push_back(0.06f * float(i), 0.06f, -0.06f * float(i));  // across the origin
  }
  in.push_back(1e9f, -1e9f, 3e8f);  // beyond 2^20 voxels: clamped
  in.push_back(2e9f, -2e9f, 6e8f);  // the same clamped voxel: dropped
  const double voxel = 0.125;
  const float inv = float(1.0 / voxel);
  auto index = [inv](float v) {
    const double c = std::floor(double(v) * double(inv)) + double(1 << 20);
    return std::int64_t(std::min(std::max(0.0, c), double((1 << 21) - 1)));
  };
  std::set<std::tuple<std::int64_t, std::int64_t, std::int64_t>> seen;
  PointArray expected;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (seen.insert({index(in.x[i]), index(in.y[i]), index(in.z[i])}).second) {
      expected.push_back(in.x[i], in.y[i], in.z[i]);
    }
  }
  ASSERT_LT(expected.size(), in.size());
  for (const SimdPath path : simdPathsToCompare()) {
    setSimdPath(path);
    const PointArray out = collapseToVoxels(in, voxel);
    ASSERT_EQ(out.size(), expected.size()) << simdPathName(path);
    EXPECT_TRUE(std::equal(out.x.begin(), out.x.end(), expected.x.begin()) &&
                std::equal(out.y.begin(), out.y.end(), expected.y.begin()) &&
                std::equal(out.z.begin(), out.z.end(), expected.z.begin()))
        << simdPathName(path);
  }
  setSimdPath(std::nullopt);
}
