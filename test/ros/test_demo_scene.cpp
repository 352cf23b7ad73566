// rostest of the whole demo chain in one scene: simulator_node -> ScanMatcherNodelet ->
// SweepEvaluator, with the paper's "big" odometry errors (+-1 m, +-8 deg per increment);
// demo_scene.test (stop-and-go sweeps) and demo_lines.test (LaserScan lines while driving,
// through SweepAssemblerNodelet, de-skewed by the matcher). Every increment must be within
// ~max_es [m] / ~max_ea [deg] of the truth (default 15 mm / 0.045 deg, just under twice the
// largest of the four scenes: 7.5 mm / 0.0242 deg), every sweep accepted, and status and registered_cloud published
// for each sweep. While the demo runs, map -> base_link must be available at the current time
// within ~tf_wait [s] (default 0.3 s, a costmap's default transform_tolerance; map -> odom
// post-dated, as a navigation stack needs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include <ros/ros.h>
#include <tf2_ros/transform_listener.h>

#include "cube_scan_matcher/ros_tools/sweep_evaluator.h"

using cube_scan_matcher::SweepEvaluator;

TEST(DemoScene, EveryIncrementMatchesTheTruth) {
  ros::NodeHandle nh, pnh("~");
  const int sweeps = pnh.param("sweeps", 5);
  const double max_es = pnh.param("max_es", 0.015), max_ea = pnh.param("max_ea", 0.045);
  const double tf_wait = pnh.param("tf_wait", 0.3);
  SweepEvaluator evaluator(nh, "ground_truth", "scan_matcher");
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);
  int lookups = 0, lookups_ok = 0;
  std::string lookup_error;
  ros::WallTime next_lookup = ros::WallTime::now();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(pnh.param("timeout", 120.0));
  while (ros::ok() && int(evaluator.rows().size()) < sweeps && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (!evaluator.rows().empty() && ros::WallTime::now() >= next_lookup) {
      // As a costmap would: map -> base_link at the current time, waiting at most tf_wait (the
      // odometry comes at 50 Hz or more, so its latest is 20 ms old, more on a loaded machine).
      ++lookups;
      std::string error;
      if (tf_buffer.canTransform("map", "base_link", ros::Time::now(), ros::Duration(tf_wait), &error)) {
        ++lookups_ok;
      } else {
        lookup_error = error;
      }
      next_lookup += ros::WallDuration(0.25);
    }
    ros::WallDuration(0.02).sleep();
  }
  ros::WallDuration(0.3).sleep();
  ros::spinOnce();
  std::printf("%s\n", SweepEvaluator::header().c_str());
  for (const auto& r : evaluator.rows()) std::printf("%s\n", SweepEvaluator::format(r).c_str());
  std::printf("%s\n", evaluator.summary().c_str());
  ASSERT_EQ(int(evaluator.rows().size()), sweeps) << "not every sweep was evaluated in time";
  EXPECT_GE(evaluator.registeredClouds(), sweeps);
  std::printf("map -> base_link at the current time: %d of %d lookups\n", lookups_ok, lookups);
  EXPECT_GE(lookups, 8);
  // A miss in 20 is tolerated (at least one): on this 2-core machine, with the simulator, the
  // manager and a registration's two search threads sharing the cores, one lookup in 65 has
  // been seen to find the chain's latest data 22 ms short of now after the full tf_wait (with the
  // manager's default 2 worker threads, one held by the registration, two in 65 were up to 0.42 s
  // short: the launch file gives its manager 4 worker threads).
  EXPECT_GE(lookups_ok, lookups - std::max(1, lookups / 20)) << "last error: " << lookup_error;
  double worst_es = 0.0, worst_ea = 0.0;
  for (const auto& r : evaluator.rows()) {
    EXPECT_GT(evaluator.cloudPoints(r.stamp), 1000u) << "sweep " << r.sweep << ": no registered_cloud";
    if (r.sweep == 0) {
      EXPECT_EQ(r.reason, "first_scan");
      continue;
    }
    EXPECT_TRUE(r.accepted) << "sweep " << r.sweep << " rejected: " << r.reason;
    EXPECT_LT(r.inc_es, max_es) << "sweep " << r.sweep;
    EXPECT_LT(r.inc_ea, max_ea) << "sweep " << r.sweep;
    worst_es = std::max(worst_es, r.inc_es);
    worst_ea = std::max(worst_ea, r.inc_ea);
  }
  // The tolerances are set near twice these: the log says how close each run came.
  std::printf("largest increment error checked: %.4f m / %.4f deg\n", worst_es, worst_ea);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_demo_scene");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
