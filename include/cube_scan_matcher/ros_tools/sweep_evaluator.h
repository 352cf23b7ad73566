// Compares the scan matcher's poses with the simulator's ground truth, sweep by sweep, with the
// paper's errors (eqs. 7-8): Es = translation error [m], Ea = root of the summed squared
// roll/pitch/yaw errors [deg], for each increment and for the accumulated pose. Used by the
// sim_evaluator node (demo) and by the per-scene rostest.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include "cube_scan_matcher/Status.h"

namespace cube_scan_matcher {

struct SweepRow {
  int sweep = 0;                ///< 0 = the first (reference) sweep
  ros::Time stamp;
  std::string reason;           ///< Status.reason_text, or "dropped" (never answered)
  bool accepted = false;
  double guess_es = 0, guess_ea = 0;  ///< odometry increment error [m], [deg]
  double inc_es = 0, inc_ea = 0;      ///< registered increment error [m], [deg]
  double acc_es = 0, acc_ea = 0;      ///< accumulated pose error [m], [deg]
  double latency = 0;           ///< [s] Status.latency
};

class SweepEvaluator {
 public:
  /// Subscribes `truth_topic` (PoseStamped) and the matcher's topics under `matcher_ns`.
  SweepEvaluator(ros::NodeHandle& nh, const std::string& truth_topic, const std::string& matcher_ns);

  /// Rows complete so far (truth, pose and status seen for the sweep and the one before).
  const std::vector<SweepRow>& rows() const { return rows_; }
  int registeredClouds() const { return clouds_; }
  /// Points of the registered_cloud stamped `stamp` (0 if none arrived).
  std::uint32_t cloudPoints(const ros::Time& stamp) const {
    auto it = cloud_points_.find(stamp);
    return it == cloud_points_.end() ? 0u : it->second;
  }
  static std::string header();
  static std::string format(const SweepRow& row);
  /// Median and max of the increment errors, success count (Es < 0.10 m, Ea < 1 deg).
  std::string summary() const;

 private:
  struct Sweep {
    bool has_truth = false, has_pose = false, has_status = false;
    Eigen::Isometry3d truth, pose;
    Status status;
  };
  void update();

  std::map<ros::Time, Sweep> sweeps_;
  std::optional<ros::Time> last_posed_;  // the last sweep with a pose (the increments' start)
  std::vector<SweepRow> rows_;
  int clouds_ = 0;
  std::map<ros::Time, std::uint32_t> cloud_points_;
  ros::Subscriber truth_sub_, pose_sub_, status_sub_, cloud_sub_;
};

}  // namespace cube_scan_matcher
