// CubeGrid: V and L of eqs. 3-6, the inclusive upper bound, the memory guard, bad settings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/simd_path.h"
#include "simd_test_paths.h"
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

namespace {
// Restores the automatic SIMD path when a test that forces one ends.
struct SimdPathGuard {
  ~SimdPathGuard() { setSimdPath(std::nullopt); }
};
}  // namespace

TEST(SimdPath, EveryPathGivesTheIndicesOfThePortableOne) {
  // Random rotations and translations, points inside, outside, on cube faces (x.5 after the
  // affine's +0.5) and non-finite: every vector path must write the same indices.
  SimdPathGuard guard;
  const std::vector<SimdPath> paths = simdPathsToCompare();
  ASSERT_FALSE(paths.empty());
  EXPECT_EQ(paths.back(), SimdPath::Portable);
  PointArray ref;
  ref.push_back(-20, -15, -3);
  ref.push_back(25, 30, 8);
  const CubeGrid g = CubeGrid::build(ref, edge(0.5));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(-30.f, 35.f);
  // Not a multiple of any vector width; enough points that a rounding difference (an FMA on
  // one path only) moves some index across a face.
  const std::size_t n = 400009;
  std::vector<float> x(n), y(n), z(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = u(rng), y[i] = u(rng), z[i] = u(rng) / 3;
    // (k + 0.25 + 20) / 0.5 + 0.5 is an integer: on a cube face under the identity (trial 0).
    if (i % 97 == 0) x[i] = std::round(x[i]) + 0.25f;
    if (i % 101 == 0) y[i] = std::numeric_limits<float>::quiet_NaN();
    if (i % 103 == 0) z[i] = -std::numeric_limits<float>::infinity();
  }
  for (int trial = 0; trial < 20; ++trial) {
    Pose6 p = Pose6::Zero();
    if (trial > 0) {
      for (int k = 0; k < 6; ++k) p[k] = std::uniform_real_distribution<double>(-1, 1)(rng);
    }
    const Eigen::Isometry3d t = poseToIsometry(p);
    const GridAffine a = g.affine(t.linear().cast<float>(), t.translation().cast<float>());
    setSimdPath(SimdPath::Portable);
    EXPECT_EQ(activeSimdPath(), SimdPath::Portable);
    std::vector<std::int32_t> want(n), got(n);
    computeCubeIndices(a, g.dimsF(), x.data(), y.data(), z.data(), n, -7, want.data());
    EXPECT_GT(std::count_if(want.begin(), want.end(), [](std::int32_t i) { return i >= 0; }),
              std::ptrdiff_t(n / 10));  // a real share of the points is inside
    for (SimdPath path : paths) {
      setSimdPath(path);
      EXPECT_EQ(activeSimdPath(), path);
      computeCubeIndices(a, g.dimsF(), x.data(), y.data(), z.data(), n, -7, got.data());
      std::size_t differ = 0;
      for (std::size_t i = 0; i < n; ++i) differ += got[i] != want[i];
      EXPECT_EQ(differ, 0u) << simdPathName(path) << " trial " << trial;
    }
  }
}

TEST(SimdPath, NamesParseAndBadOnesAreRefused) {
  SimdPathGuard guard;
  for (SimdPath p : {SimdPath::Avx512, SimdPath::Avx2, SimdPath::Portable}) {
    EXPECT_EQ(parseSimdPath(simdPathName(p)), p);
  }
  EXPECT_EQ(parseSimdPath("auto"), std::nullopt);
  try {
    parseSimdPath("avx3");
    FAIL() << "avx3 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("avx3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("portable"), std::string::npos) << e.what();
  }
  // The automatic choice is the fastest supported path; an unsupported one is refused.
  setSimdPath(std::nullopt);
  EXPECT_EQ(activeSimdPath(), supportedSimdPaths().front());
  for (SimdPath p : {SimdPath::Avx512, SimdPath::Avx2}) {
    if (!simdPathSupported(p)) {
      EXPECT_THROW(setSimdPath(p), std::invalid_argument);
    }
  }
  EXPECT_NE(simdReport().find(simdPathName(activeSimdPath())), std::string::npos);
}

TEST(LargeBuffer, BigBlocksStartOnAHugePageAndKeepTheirContents) {
  LargeBuffer<std::uint64_t> big(300000, 7);  // 2.4 MB
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(big.data()) % LargeBufferAllocator<std::uint64_t>::kHugePage, 0u);
  big.resize(600000, 9);  // grows into a new block: the old contents are copied
  EXPECT_EQ(big[299999], 7u);
  EXPECT_EQ(big[300000], 9u);
  LargeBuffer<std::uint8_t> small(100, 3);  // an ordinary block
  EXPECT_EQ(std::count(small.begin(), small.end(), 3), 100);
}

TEST(CubeGrid, RebuiltAfterALargerGridAndAnErrorEqualsAFreshOne) {
  // V is zeroed through L, not wholesale: a rebuild into the memory of a larger grid, and one
  // after a refused extent, must leave no stale bit.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-20.f, 20.f), s(-3.f, 3.f);
  PointArray big, small;
  for (int i = 0; i < 20000; ++i) big.push_back(u(rng), u(rng), u(rng) / 4);
  for (int i = 0; i < 3000; ++i) small.push_back(s(rng), s(rng), s(rng));
  const CubeGridSettings settings = edge(0.25);
  CubeGrid reused = CubeGrid::build(big, settings);
  PointArray absurd = small;
  absurd.push_back(1e6f, 0.f, 0.f);
  EXPECT_THROW(reused.rebuild(absurd, settings), CubeGridError);
  EXPECT_EQ(reused.occupiedCount(), 0u);
  reused.rebuild(small, settings);
  const CubeGrid fresh = CubeGrid::build(small, settings);
  EXPECT_EQ(reused.dims(), fresh.dims());
  EXPECT_EQ(reused.list(), fresh.list());
  ASSERT_EQ(reused.bits().size(), fresh.bits().size());
  EXPECT_TRUE(std::equal(fresh.bits().begin(), fresh.bits().end(), reused.bits().begin()));
  reused.rebuild(big, settings);  // and growing again within the kept memory
  const CubeGrid fresh_big = CubeGrid::build(big, settings);
  EXPECT_EQ(reused.list(), fresh_big.list());
  EXPECT_TRUE(std::equal(fresh_big.bits().begin(), fresh_big.bits().end(), reused.bits().begin()));
}
