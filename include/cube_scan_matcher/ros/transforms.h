// Eigen <-> geometry_msgs helpers shared by the nodes and tests.
#pragma once

#include <string>

#include <Eigen/Geometry>
#include <geometry_msgs/TransformStamped.h>
#include <tf2_eigen/tf2_eigen.h>

namespace cube_scan_matcher {

/// T (child -> parent, p_parent = T p_child) as a stamped tf message.
inline geometry_msgs::TransformStamped stampedTransform(const Eigen::Isometry3d& T,
                                                        const std::string& parent,
                                                        const std::string& child,
                                                        const ros::Time& stamp) {
  geometry_msgs::TransformStamped t = tf2::eigenToTransform(T);
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  return t;
}

}  // namespace cube_scan_matcher
