// Helpers shared by the rostests that drive ScanMatcherNodelet: the collected outputs, a spin
// loop with a timeout, and a cloud from a PointArray.
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"

namespace cube_scan_matcher::test {

/// The largest pose error a test binary met, printed when it exits: the tolerances of its
/// checks are set near twice these (a real regression must fail them), and the log says how
/// close each run came.
struct WorstError {
  double m = 0.0, deg = 0.0;
  int checked = 0;
  void add(const Eigen::Isometry3d& error) {
    ++checked;
    m = std::max(m, error.translation().norm());
    deg = std::max(deg, Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI);
  }
  ~WorstError() {
    if (checked > 0)
      std::printf("largest pose error of %d checked: %.4f m / %.4f deg\n", checked, m, deg);
  }
};

/// Every message of each output of the matcher whose private namespace is `ns` ("/name/").
struct Outputs {
  std::vector<Status> status;
  std::vector<geometry_msgs::PoseWithCovarianceStamped> pose;
  std::vector<nav_msgs::Odometry> odom;
  std::vector<sensor_msgs::PointCloud2> cloud;  // header and width only: keeps memory small
  nav_msgs::Path path;
  ros::Subscriber subs[5];

  Outputs(ros::NodeHandle& nh, const std::string& ns) {
    using PoseMsg = geometry_msgs::PoseWithCovarianceStamped;
    subs[0] = nh.subscribe<Status>(ns + "status", 100,
                                   [this](const Status::ConstPtr& m) { status.push_back(*m); });
    subs[1] = nh.subscribe<PoseMsg>(ns + "pose", 100,
                                    [this](const PoseMsg::ConstPtr& m) { pose.push_back(*m); });
    subs[2] = nh.subscribe<nav_msgs::Odometry>(
        ns + "odometry", 100, [this](const nav_msgs::Odometry::ConstPtr& m) { odom.push_back(*m); });
    subs[3] = nh.subscribe<sensor_msgs::PointCloud2>(
        ns + "registered_cloud", 100, [this](const sensor_msgs::PointCloud2::ConstPtr& m) {
          sensor_msgs::PointCloud2 c;
          c.header = m->header;
          c.width = m->width;
          cloud.push_back(c);
        });
    subs[4] = nh.subscribe<nav_msgs::Path>(ns + "path", 5,
                                           [this](const nav_msgs::Path::ConstPtr& m) { path = *m; });
  }

  /// The status published for the cloud stamped `stamp`, or null.
  const Status* statusAt(const ros::Time& stamp) const {
    for (auto it = status.rbegin(); it != status.rend(); ++it) {
      if (it->header.stamp == stamp) return &*it;
    }
    return nullptr;
  }
  /// The pose published for the cloud stamped `stamp`, or null.
  const geometry_msgs::PoseWithCovarianceStamped* poseAt(const ros::Time& stamp) const {
    for (auto it = pose.rbegin(); it != pose.rend(); ++it) {
      if (it->header.stamp == stamp) return &*it;
    }
    return nullptr;
  }
};

/// Spins until `done()` or `timeout` [s] of wall time pass; returns done().
template <typename F>
bool waitFor(F done, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.01).sleep();
  }
  ros::spinOnce();
  return done();
}

/// Every status published on /diagnostics, appended to `out` while the subscriber lives.
inline ros::Subscriber collectDiagnostics(ros::NodeHandle& nh,
                                          std::vector<diagnostic_msgs::DiagnosticStatus>& out) {
  return nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&out](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status) out.push_back(s);
      });
}

/// Spins for `seconds` of wall time.
inline void spinFor(double seconds) {
  waitFor([] { return false; }, seconds);
}

inline sensor_msgs::PointCloud2 makeCloud(const PointArray& pts, const std::string& frame,
                                          const ros::Time& stamp) {
  std_msgs::Header h;
  h.frame_id = frame;
  h.stamp = stamp;
  return toCloud(pts, Eigen::Isometry3d::Identity(), h);
}

}  // namespace cube_scan_matcher::test
