// rostest of the whole demo chain in one scene: simulator_node -> ScanMatcherNodelet ->
// SweepEvaluator, with the paper's "big" odometry errors (+-1 m, +-8 deg per increment).
// Every increment must be within 5 cm / 0.5 deg of the truth, every sweep accepted, and
// status and registered_cloud published for each sweep.
#include <gtest/gtest.h>

#include <cstdio>

#include <ros/ros.h>

#include "cube_scan_matcher/ros_tools/sweep_evaluator.h"

using cube_scan_matcher::SweepEvaluator;

TEST(DemoScene, EveryIncrementMatchesTheTruth) {
  ros::NodeHandle nh, pnh("~");
  const int sweeps = pnh.param("sweeps", 5);
  SweepEvaluator evaluator(nh, "ground_truth", "scan_matcher");
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout", 120.0));
  while (ros::ok() && int(evaluator.rows().size()) < sweeps && ros::WallTime::now() < end) {
    ros::spinOnce();
    ros::WallDuration(0.02).sleep();
  }
  ros::WallDuration(0.3).sleep();
  ros::spinOnce();
  std::printf("%s\n", SweepEvaluator::header().c_str());
  for (const auto& r : evaluator.rows()) std::printf("%s\n", SweepEvaluator::format(r).c_str());
  std::printf("%s\n", evaluator.summary().c_str());
  ASSERT_EQ(int(evaluator.rows().size()), sweeps) << "not every sweep was evaluated in time";
  EXPECT_GE(evaluator.registeredClouds(), sweeps);
  for (const auto& r : evaluator.rows()) {
    EXPECT_GT(evaluator.cloudPoints(r.stamp), 1000u) << "sweep " << r.sweep << ": no registered_cloud";
    if (r.sweep == 0) {
      EXPECT_EQ(r.reason, "first_scan");
      continue;
    }
    EXPECT_TRUE(r.accepted) << "sweep " << r.sweep << " rejected: " << r.reason;
    EXPECT_LT(r.inc_es, 0.05) << "sweep " << r.sweep;
    EXPECT_LT(r.inc_ea, 0.5) << "sweep " << r.sweep;
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_demo_scene");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
