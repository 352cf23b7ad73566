// The refine objective: the sum of fine J plus w x J on the E grid, over a pivoted variable.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "cube_scan_matcher/core/multi_scale_objective.h"
#include "cube_scan_matcher/core/simd_path.h"
#include "simd_test_paths.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(MultiScaleObjective, IsTheSumOfFineJPlusTheWeightedCoarseJ) {
  const PointArray ref = cornerScene(4000, 3);
  CubeGridSettings fine_settings = edge(0.25);
  const CubeGrid coarse_grid = CubeGrid::build(ref, edge(0.5));
  const CubeGrid fine0 = CubeGrid::build(ref, fine_settings);
  fine_settings.origin_shift = 0.5;
  const CubeGrid fine1 = CubeGrid::build(ref, fine_settings);
  CoincidenceObjective coarse(coarse_grid, ref), f0(fine0, ref), f1(fine1, ref);
  const Eigen::Vector3d pivot = centroid(ref);
  MultiScaleObjective f({&f0, &f1}, &coarse, 3.0, pivot);

  Pose6 p = Pose6::Zero();
  p << 0.2, -0.1, 0.05, 0.01, 0.02, -0.03;
  const Vector6d q = f.variable(p);
  EXPECT_TRUE(f.pose(q).isApprox(p, 1e-12));
  EXPECT_DOUBLE_EQ(f(q), double(f0(p) + f1(p)) + 3.0 * double(coarse(p)));
  // At the identity the variable is the pivot itself, and every grid is fully matched.
  EXPECT_TRUE(f.variable(Pose6::Zero()).head<3>().isApprox(pivot, 1e-12));
  EXPECT_DOUBLE_EQ(f(f.variable(Pose6::Zero())),
                   double(fine0.occupiedCount() + fine1.occupiedCount()) +
                       3.0 * double(coarse_grid.occupiedCount()));
  // With w = 0 the E grid is not evaluated at all.
  MultiScaleObjective fine_only({&f0, &f1}, nullptr, 0.0, pivot);
  EXPECT_DOUBLE_EQ(fine_only(q), double(f0(p) + f1(p)));
}

// All grids in one pass (one rotation per block of points, the grids' edges E/2 and E) give
// exactly the J of each grid evaluated on its own, on every vector path, with a working copy
// of a byte or a bit per cube; grids whose edges are not E/2^k are evaluated one by one.
TEST(MultiScaleObjective, GridsEvaluatedTogetherGiveEachGridsJ) {
  const PointArray ref = cornerScene(6000, 5);
  const PointArray scan = transformed(cornerScene(5000, 6), poseToIsometry(shift(0.3, -0.2)));
  for (const std::uint64_t max_byte_cubes : {std::uint64_t{1} << 24, std::uint64_t{0}}) {
    CubeGridSettings fs = edge(0.25), cs = edge(0.5), odd = edge(0.3);
    fs.max_byte_cubes = cs.max_byte_cubes = odd.max_byte_cubes = max_byte_cubes;
    std::vector<CubeGrid> fine;
    for (int k = 0; k < 3; ++k) {
      fs.origin_shift = k / 3.0;
      fine.push_back(CubeGrid::build(ref, fs));
    }
    const CubeGrid coarse_grid = CubeGrid::build(ref, cs), odd_grid = CubeGrid::build(ref, odd);
    std::vector<CoincidenceObjective> f;
    for (const CubeGrid& g : fine) f.emplace_back(g, scan);
    CoincidenceObjective coarse(coarse_grid, scan), other(odd_grid, scan);
    const Eigen::Vector3d pivot = centroid(scan);
    MultiScaleObjective together({&f[0], &f[1], &f[2]}, &coarse, 3.0, pivot);
    MultiScaleObjective one_by_one({&f[0], &other}, &coarse, 3.0, pivot);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const SimdPath path : simdPathsToCompare()) {
      setSimdPath(path);
      for (int trial = 0; trial < 40; ++trial) {
        Pose6 p;
        p << 0.5 * u(rng), 0.5 * u(rng), 0.2 * u(rng), 0.1 * u(rng), 0.1 * u(rng), 0.6 * u(rng);
        const double expected =
            double(f[0](p) + f[1](p) + f[2](p)) + 3.0 * double(coarse(p));
        EXPECT_EQ(together(together.variable(p)), expected) << simdPathName(path);
        EXPECT_TRUE(together.evaluatedTogether());
        EXPECT_EQ(one_by_one(one_by_one.variable(p)),
                  double(f[0](p) + other(p)) + 3.0 * double(coarse(p)));
        EXPECT_FALSE(one_by_one.evaluatedTogether());
      }
      for (const CoincidenceObjective& o : f) EXPECT_TRUE(o.workingCopyRestored());
      EXPECT_TRUE(coarse.workingCopyRestored());
    }
  }
  setSimdPath(std::nullopt);
}

TEST(MultiScaleObjective, AnAngleStepTurnsThePointsAboutThePivot) {
  // Changing only the yaw of q keeps the pivot where it is: R c + t stays q's translation.
  const Eigen::Vector3d c(4.0, 5.0, 1.0);
  MultiScaleObjective f({}, nullptr, 0.0, c);
  Vector6d q = f.variable(Pose6::Zero());
  q[5] += deg2rad(10.0);
  EXPECT_TRUE((poseToIsometry(f.pose(q)) * c).isApprox(c, 1e-12));
}

TEST(MultiScaleObjective, CentroidOfPoints) {
  PointArray p;
  p.push_back(0, 0, 0);
  p.push_back(2, 4, 6);
  EXPECT_TRUE(centroid(p).isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(centroid(PointArray{}).isZero());
}
