// The paper's errors (eqs. 7-8) on known poses.
#include <gtest/gtest.h>

#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

TEST(Metrics, Eq7IsTheTranslationDistanceAndEq8TheRootOfTheSquaredAngleErrors) {
  Pose6 a = Pose6::Zero(), b = Pose6::Zero();
  a.head<3>() << 1.0, 2.0, 3.0;
  b.head<3>() << 1.3, 2.4, 3.0;
  a[3] = deg2rad(4.0);   // roll error 4 deg
  a[5] = deg2rad(3.0);   // yaw error 3 deg
  const PoseError e = poseError(poseToIsometry(a), poseToIsometry(b));
  EXPECT_NEAR(e.es_m, 0.5, 1e-12);
  EXPECT_NEAR(e.ea_deg, 5.0, 1e-9);
}

TEST(Metrics, AnglesAreWrappedBeforeSquaring) {
  Pose6 a = Pose6::Zero(), b = Pose6::Zero();
  a[5] = deg2rad(179.0);
  b[5] = deg2rad(-179.0);
  EXPECT_NEAR(poseError(poseToIsometry(a), poseToIsometry(b)).ea_deg, 2.0, 1e-9);
  EXPECT_NEAR(poseError(poseToIsometry(a), poseToIsometry(a)).ea_deg, 0.0, 1e-12);
}

TEST(Metrics, QuantileIsTheSortedElementAtFloorQn) {
  EXPECT_EQ(quantile({}, 0.5), 0.0);
  EXPECT_EQ(quantile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 0.5), 3.0);  // index 2 of 4, no averaging
  EXPECT_EQ(quantile({5.0, 1.0, 4.0}, 1.0), 5.0);
  EXPECT_EQ(quantile({5.0, 1.0, 4.0}, 0.0), 1.0);
}
