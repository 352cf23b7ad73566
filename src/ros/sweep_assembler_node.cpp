// sweep_assembler_node: SweepAssemblerNodelet as a stand-alone node. It only loads the nodelet
// (one implementation); remappings and private parameters pass through.
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "sweep_assembler");
  nodelet::Loader loader;
  nodelet::M_string remap(ros::names::getRemappings());
  nodelet::V_string nargv;
  if (!loader.load(ros::this_node::getName(), "cube_scan_matcher/SweepAssemblerNodelet", remap,
                   nargv)) {
    ROS_FATAL("could not load cube_scan_matcher/SweepAssemblerNodelet");
    return 1;
  }
  ros::spin();
  return 0;
}
