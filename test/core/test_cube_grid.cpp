#include <gtest/gtest.h>

#include <cmath>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/cube_grid.h"

using namespace cube_scan_matcher;

namespace {
PointArray lineOfCubeCentres(int n, double e) {
  PointArray p;
  for (int i = 0; i < n; ++i) p.push_back(float(i * e), 0.f, 0.f);
  return p;
}
CubeGridSettings edge(double e) {
  CubeGridSettings s;
  s.cube_edge = e;
  return s;
}
Pose6 shift(double x, double y = 0, double z = 0) {
  Pose6 p = Pose6::Zero();
  p.head<3>() << x, y, z;
  return p;
}
}  // namespace

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
  int previous = -1;
  for (int k = 0; k < 50; ++k) {
    Pose6 pose;
    pose << 0.05 * k, -0.03 * k, 0.01 * k, 0.01 * k, -0.02 * k, 0.03 * k;
    const int value = j.evaluate(pose);
    EXPECT_TRUE(j.workingCopyRestored()) << "after evaluation " << k;
    EXPECT_EQ(j.evaluate(pose), value);  // same pose, same J: nothing left cleared
    if (k == 0) {
      EXPECT_EQ(value, int(g.occupiedCount()));
    }
    previous = value;
  }
  EXPECT_GE(previous, 0);
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
