// Every parameter of ScanMatcherNodelet, read and validated in one place. Out-of-range values
// raise ParamError naming the parameter; the nodelet refuses to start with it. The same names,
// units and defaults are in config/scan_matcher.yaml, cfg/ScanMatcher.cfg and docs/parameters.md.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "cube_scan_matcher/ScanMatcherConfig.h"
#include "cube_scan_matcher/core/chain_covariance.h"
#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/odometry_anchor.h"
#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/ros/read_param.h"

namespace cube_scan_matcher {

struct NodeParams {
  // Frames.
  std::string base_frame = "base_link";  ///< robot frame the scans are registered in.
  std::string odom_frame = "odom";       ///< frame of the DGPS/IMU odometry; "" = none.
  std::string map_frame = "map";         ///< frame of the published poses and clouds.
  /// A robot without odometry (odom_frame ""): no lookup, the motion model predicts each scan.
  bool hasOdometry() const { return !odom_frame.empty(); }
  // tf.
  double tf_timeout = 0.1;        ///< [s] bounded wait for each tf lookup, in [0, 10].
  /// [s] a scan stamped earlier than the last one by less than this is out of order: dropped
  /// and counted; by more, time went back (bag loop, clock reset) and the state is reset.
  double time_jump_reset = 1.0;
  bool skip_without_tf = false;   ///< missing_tf_policy: "skip" (true) or "predict" (false).
  /// What the node is in a REP-105 tree (README "Using it on a robot"):
  ///  - Messages: pose, odometry and path only, no tf: a filter (robot_localization) fuses them;
  ///  - MapOdom: also map -> odom from the chain (map drifts from odom along the run);
  ///  - Anchored: map -> odom from the chain tied to the odometry (odometry_anchor.h), so that
  ///    map stays within the odometry's error of odom; the pose topics carry that pose.
  enum class Role { Messages, MapOdom, Anchored } role = Role::Messages;
  OdometryAnchorSettings anchor;  ///< Anchored: the odometry's absolute accuracy.
  double transform_tolerance = 0.1;  ///< [s] map -> odom is post-dated by this, in [0, 10].
  bool publishesTf() const { return role != Role::Messages; }
  /// ~reset: the new chain starts at the last published pose moved on by the odometry (map
  /// stays continuous) instead of at the next scan's odometry pose.
  bool reset_continuous = false;
  double tf_rate = 20.0;          ///< [Hz] map -> odom re-sent at this rate, in [0.1, 1000].
  // Input and outputs.
  int queue_size = 1;             ///< subscriber queue, in [1, 100].
  int path_max_length = 10000;    ///< poses kept in ~path, in [1, 1e6].
  RangeFilterSettings filter;     ///< range_min, range_max [m] around the base_frame origin.
  /// Field of the per-point times [s, relative to the stamp] (the sweep assembler's "time");
  /// empty: none read. Clouds without it are rigid sweeps.
  std::string time_field = "time";
  /// Covariance of the published pose along the chain (ROS parameters sigma_translation [m],
  /// sigma_rotation_deg [deg], registration_sigma_scale, drift_percent [%],
  /// rejected_sigma_translation [m], rejected_sigma_rotation_deg [deg]).
  ChainCovarianceSettings chain;
  // Diagnostics.
  double min_rate = 0.05;         ///< [Hz] input rate below this is a WARN.
  double max_rate = 100.0;        ///< [Hz] input rate above this is a WARN.
  double max_latency = 1.0;       ///< [s] processing latency above this is a WARN.
  // The algorithm and the gate (live through dynamic_reconfigure).
  OnlineMatcherSettings matcher;
};

/// Reads every parameter from the private node handle, with defaults for those not set.
/// Throws ParamError naming the first bad one.
NodeParams loadParams(const ros::NodeHandle& pnh);

/// Every parameter name loadParams reads (the fixed ones and the cfg's live ones): a name set
/// under the nodelet's namespace and not in this list is warned about (unknownParamWarnings).
const std::vector<std::string>& knownParamNames();

/// Applies the live parameters of a dynamic_reconfigure request to `params.matcher`. Throws
/// ParamError if the combination is invalid (params unchanged then).
void applyConfig(const ScanMatcherConfig& config, NodeParams& params);

/// The live parameters of `params` as a dynamic_reconfigure config.
ScanMatcherConfig toConfig(const NodeParams& params);

}  // namespace cube_scan_matcher
