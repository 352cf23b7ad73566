// sim_evaluator: prints the matcher's per-sweep errors against the simulator's ground truth and
// a summary. With ~sweeps > 0 it exits after that many sweeps (the demo ends with it).
#include <cstdio>

#include <ros/ros.h>

#include "cube_scan_matcher/ros_tools/sweep_evaluator.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "sim_evaluator");
  ros::NodeHandle nh, pnh("~");
  const int sweeps = pnh.param("sweeps", 0);
  const std::string ns = pnh.param<std::string>("matcher_ns", "scan_matcher");
  cube_scan_matcher::SweepEvaluator evaluator(nh, "ground_truth", ns);
  std::printf("%s\n", cube_scan_matcher::SweepEvaluator::header().c_str());
  std::fflush(stdout);
  std::size_t printed = 0;
  ros::Rate rate(50);
  while (ros::ok()) {
    ros::spinOnce();
    for (; printed < evaluator.rows().size(); ++printed) {
      std::printf("%s\n", cube_scan_matcher::SweepEvaluator::format(evaluator.rows()[printed]).c_str());
      std::fflush(stdout);
    }
    if (sweeps > 0 && int(printed) >= sweeps) break;
    rate.sleep();
  }
  std::printf("%s\n", evaluator.summary().c_str());
  std::fflush(stdout);
  return 0;
}
