// CoincidenceObjective: J of section 2.1 on small grids, V restored, byte and bit copies.
#include <gtest/gtest.h>

#include <cmath>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/cube_grid.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(CoincidenceObjective, ReferenceAgainstItselfAtIdentityGivesL) {
  PointArray p;
  for (int i = 0; i < 2000; ++i) {
    p.push_back(float(std::sin(i * 0.37) * 9), float(std::cos(i * 0.11) * 7), float((i % 13) * 0.31));
  }
  const CubeGrid g = CubeGrid::build(p, edge(0.5));
  CoincidenceObjective j(g, p);
  EXPECT_EQ(j.evaluate(Pose6::Zero()), int(g.occupiedCount()));
}

TEST(CoincidenceObjective, OneCubeShift) {
  // Reference: 4 cubes in a row. The scan shifted by +1 cube along x leaves the grid with its
  // last point and misses the first cube: J = 3. Shifted by +-0.4 E it stays in its cubes.
  const PointArray p = lineOfCubeCentres(4, 1.0);
  const CubeGrid g = CubeGrid::build(p, edge(1.0));
  CoincidenceObjective j(g, p);
  EXPECT_EQ(j.evaluate(shift(1.0)), 3);
  EXPECT_EQ(j.evaluate(shift(-1.0)), 3);
  EXPECT_EQ(j.evaluate(shift(0.4)), 4);
  EXPECT_EQ(j.evaluate(shift(0.0, 1.0)), 0);  // off the grid sideways
  EXPECT_EQ(j.evaluate(shift(3.0)), 1);
}

TEST(CoincidenceObjective, DuplicatePointsDoNotChangeJ) {
  const PointArray p = lineOfCubeCentres(6, 0.5);
  PointArray dup = p;
  for (int k = 0; k < 7; ++k) {
    for (std::size_t i = 0; i < p.size(); ++i) dup.push_back(p.x[i], p.y[i] + 0.01f * k, p.z[i]);
  }
  const CubeGrid g = CubeGrid::build(p, edge(0.5));
  CoincidenceObjective once(g, p), many(g, dup);
  for (double dx : {0.0, 0.3, 0.5, 1.0, -0.7}) {
    EXPECT_EQ(once.evaluate(shift(dx)), many.evaluate(shift(dx))) << dx;
  }
}

TEST(CoincidenceObjective, VIsRestoredAfterEveryEvaluation) {
  PointArray p;
  for (int i = 0; i < 3000; ++i) p.push_back(float(i % 40) * 0.3f, float(i / 40 % 30) * 0.3f, float(i % 7) * 0.2f);
  const CubeGrid g = CubeGrid::build(p, edge(0.5));
  CoincidenceObjective j(g, p);
  int last = -1;
  for (int k = 0; k < 50; ++k) {
    Pose6 pose;
    pose << 0.05 * k, -0.03 * k, 0.01 * k, 0.01 * k, -0.02 * k, 0.03 * k;
    const int value = j.evaluate(pose);
    EXPECT_TRUE(j.workingCopyRestored()) << "after evaluation " << k;
    EXPECT_EQ(j.evaluate(pose), value);  // same pose, same J: nothing left cleared
    // J counts each occupied cube of V once, however many points fall in it.
    EXPECT_LE(value, int(g.occupiedCount())) << "after evaluation " << k;
    if (k == 0) {
      EXPECT_EQ(value, int(g.occupiedCount()));
    }
    last = value;
  }
  // 2.9 m and 26 deg from the truth the scan no longer covers every cube.
  EXPECT_LT(last, int(g.occupiedCount()));
}

namespace {
PointArray wavySurface(int n, float phase) {
  PointArray p;
  for (int i = 0; i < n; ++i) {
    p.push_back(float(std::sin(i * 0.37 + phase) * 9), float(std::cos(i * 0.11) * 7),
                float((i % 13) * 0.31));
  }
  return p;
}
}  // namespace

TEST(CoincidenceObjective, BytePerCubeAndBitPerCubeGiveTheSameJ) {
  const PointArray p = wavySurface(3000, 0.f);
  CubeGridSettings bytes = edge(0.5), bits = edge(0.5);
  bits.max_byte_cubes = 0;  // force the bit working copy
  const CubeGrid gb = CubeGrid::build(p, bytes), gv = CubeGrid::build(p, bits);
  CoincidenceObjective jb(gb, p), jv(gv, p);
  ASSERT_TRUE(jb.bytePerCube());
  ASSERT_FALSE(jv.bytePerCube());
  for (int k = 0; k < 40; ++k) {
    Pose6 pose;
    pose << 0.07 * k, -0.05 * k, 0.02 * k, 0.01 * k, -0.02 * k, 0.03 * k;
    EXPECT_EQ(jb(pose), jv(pose)) << k;
    EXPECT_TRUE(jb.workingCopyRestored());
    EXPECT_TRUE(jv.workingCopyRestored());
  }
}

TEST(CoincidenceObjective, SetGridGivesTheSameJAsAFreshObjective) {
  // Retargeting reuses the working copy (byte or bit) across grids of different sizes; J and
  // the restored copy must be those of an objective built on the new grid.
  const PointArray a = wavySurface(3000, 0.f), b = wavySurface(2500, 1.3f);
  for (std::uint64_t max_bytes : {std::uint64_t{0}, std::uint64_t{1} << 22}) {
    CubeGridSettings s = edge(0.5);
    s.max_byte_cubes = max_bytes;
    const CubeGrid ga = CubeGrid::build(a, s);
    CubeGridSettings fine = s;
    fine.cube_edge = 0.2;
    const CubeGrid gb = CubeGrid::build(b, fine);
    CoincidenceObjective moving(ga, a);
    EXPECT_EQ(moving(Pose6::Zero()), int(ga.occupiedCount()));
    moving.setGrid(gb);
    EXPECT_TRUE(moving.workingCopyRestored());
    EXPECT_EQ(moving(Pose6::Zero()), 0);  // no scan bound after setGrid
    moving.setScan(a);
    CoincidenceObjective fresh(gb, a);
    for (double dx : {0.0, 0.1, -0.4, 1.0}) EXPECT_EQ(moving(shift(dx)), fresh(shift(dx))) << dx;
    moving.setGrid(ga);  // and back to the smaller grid
    moving.setScan(b);
    CoincidenceObjective back(ga, b);
    EXPECT_EQ(moving(shift(0.3)), back(shift(0.3)));
    EXPECT_TRUE(moving.workingCopyRestored());
  }
}

TEST(CoincidenceObjective, SwitchingBetweenByteAndBitGridsGivesTheSameJ) {
  // A byte-mode grid, then a bit-mode one, and back twice: the copy of the other mode keeps its
  // memory, and must stay all zero meanwhile.
  const PointArray a = wavySurface(3000, 0.f), b = wavySurface(2500, 1.3f);
  CubeGridSettings bytes = edge(0.5), bits = edge(0.3);
  bytes.max_byte_cubes = std::uint64_t{1} << 22;
  bits.max_byte_cubes = 0;
  const CubeGrid ga = CubeGrid::build(a, bytes), gb = CubeGrid::build(b, bits);
  CoincidenceObjective moving(ga, a);
  ASSERT_TRUE(moving.bytePerCube());
  for (int round = 0; round < 2; ++round) {
    moving.setGrid(gb);
    moving.setScan(a);
    EXPECT_FALSE(moving.bytePerCube());
    CoincidenceObjective fresh_b(gb, a);
    for (double dx : {0.0, 0.2, -0.7}) EXPECT_EQ(moving(shift(dx)), fresh_b(shift(dx))) << dx;
    EXPECT_TRUE(moving.workingCopyRestored());
    moving.setGrid(ga);
    moving.setScan(b);
    EXPECT_TRUE(moving.bytePerCube());
    CoincidenceObjective fresh_a(ga, b);
    for (double dx : {0.0, 0.2, -0.7}) EXPECT_EQ(moving(shift(dx)), fresh_a(shift(dx))) << dx;
    EXPECT_TRUE(moving.workingCopyRestored());
  }
}
