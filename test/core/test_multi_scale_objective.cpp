// The refine objective: the sum of fine J plus w x J on the E grid, over a pivoted variable.
#include <gtest/gtest.h>

#include <vector>

#include "cube_scan_matcher/core/multi_scale_objective.h"
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
