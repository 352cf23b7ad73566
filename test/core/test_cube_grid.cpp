// CubeGrid: V and L of eqs. 3-6, the inclusive upper bound, the memory guard, bad settings.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cube_scan_matcher/core/cube_grid.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(CubeGrid, IndicesFollowEq5And6) {
  PointArray p;
  p.push_back(0, 0, 0);
  p.push_back(4, 3, 2);  // extent 4 x 3 x 2 m
  const CubeGrid g = CubeGrid::build(p, edge(1.0));
  EXPECT_EQ(g.dims(), Eigen::Vector3i(5, 4, 3));
  // I = Ix + Iy*Nx + Iz*Nx*Ny with Ix = round((x - xmin)/E).
  EXPECT_EQ(g.index(Eigen::Vector3f(1.2f, 2.4f, 0.6f)), 1 + 2 * 5 + 1 * 5 * 4);
  EXPECT_EQ(g.index(Eigen::Vector3f(0.49f, 0, 0)), 0);
  EXPECT_EQ(g.index(Eigen::Vector3f(0.51f, 0, 0)), 1);
}

TEST(CubeGrid, NonFinitePointsAreOutsideTheGrid) {
  // The per-point loop converts clamped floats to integers: defined for NaN and inf too (the
  // fuzzer found the NaN case undefined before the clamp was reordered).
  PointArray p;
  p.push_back(0, 0, 0);
  p.push_back(4, 3, 2);
  const CubeGrid g = CubeGrid::build(p, edge(1.0));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(g.index(Eigen::Vector3f(nan, 1, 1)), -1);
  EXPECT_EQ(g.index(Eigen::Vector3f(1, nan, 1)), -1);
  EXPECT_EQ(g.index(Eigen::Vector3f(inf, 1, 1)), -1);
  EXPECT_EQ(g.index(Eigen::Vector3f(1, 1, -inf)), -1);
}

TEST(CubeGrid, UpperBoundIsInclusive) {
  // round((xmax - xmin)/E) = Ixmax is a valid coordinate: Nx = Ixmax + 1 (the paper's eq. 3
  // would allocate Ixmax and lose the last cube).
  PointArray p;
  p.push_back(0, 0, 0);
  p.push_back(3, 0, 0);
  const CubeGrid g = CubeGrid::build(p, edge(1.0));
  EXPECT_EQ(g.dims().x(), 4);
  EXPECT_EQ(g.index(Eigen::Vector3f(3, 0, 0)), 3);
  EXPECT_TRUE(g.occupied(3));
  EXPECT_EQ(g.occupiedCount(), 2u);
  EXPECT_EQ(g.index(Eigen::Vector3f(3.6f, 0, 0)), -1);  // past the last cube
  EXPECT_EQ(g.index(Eigen::Vector3f(-0.6f, 0, 0)), -1);
}

TEST(CubeGrid, ListHoldsEachSetCubeOnce) {
  PointArray p = lineOfCubeCentres(5, 0.5);
  for (int i = 0; i < 5; ++i) p.push_back(float(i * 0.5 + 0.1), 0.05f, 0.f);  // same cubes
  const CubeGrid g = CubeGrid::build(p, edge(0.5));
  EXPECT_EQ(g.occupiedCount(), 5u);
  EXPECT_EQ(g.list().size(), 5u);
}

TEST(CubeGrid, MemoryCapTurnsAbsurdExtentIntoAClearError) {
  PointArray p;
  p.push_back(0, 0, 0);
  p.push_back(1e6f, 1e6f, 1e6f);  // a bogus point 1000 km away
  try {
    CubeGrid::build(p, edge(0.5));
    FAIL() << "expected CubeGridError";
  } catch (const CubeGridError& e) {
    EXPECT_EQ(e.code(), CubeGridError::Code::TooManyCubes);
    EXPECT_NE(std::string(e.what()).find("max_cubes"), std::string::npos);
  }
  // A tiny E over a normal extent hits the same guard.
  PointArray q;
  q.push_back(0, 0, 0);
  q.push_back(80, 80, 40);
  EXPECT_THROW(CubeGrid::build(q, edge(0.001)), CubeGridError);
}

TEST(CubeGrid, EmptyAndNonFiniteReferencesAreErrors) {
  PointArray empty;
  try {
    CubeGrid::build(empty, edge(0.5));
    FAIL();
  } catch (const CubeGridError& e) {
    EXPECT_EQ(e.code(), CubeGridError::Code::EmptyReference);
  }
  PointArray bad;
  bad.push_back(0, 0, 0);
  bad.push_back(std::nanf(""), 0, 0);
  try {
    CubeGrid::build(bad, edge(0.5));
    FAIL();
  } catch (const CubeGridError& e) {
    EXPECT_EQ(e.code(), CubeGridError::Code::NonFiniteReference);
  }
}

TEST(CubeGrid, SettingsOutOfRangeAreRefusedByName) {
  CubeGridSettings s;
  s.cube_edge = 0;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.cube_edge = 0.5;
  s.max_cubes = (std::uint64_t{1} << 31) + 1;
  try {
    validate(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_cubes"), std::string::npos);
  }
}
