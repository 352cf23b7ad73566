// ScanMatcherNodelet: the ROS face of the package, around core/online_matcher.h, which holds
// the matching itself. The nodelet converts clouds (cloud_conversion.h), reads the odometry
// and the sensor's mount from tf, calls the core, and publishes pose, odometry, path,
// registered cloud, status, optional tf and diagnostics; it also owns the services, dynamic
// reconfigure and the handling of stamps going backwards. Topics and frames: README.md;
// parameters: docs/parameters.md.
//
// Threads: the registration runs on the nodelet's own worker thread, never on a manager
// thread. The cloud callback only puts the newest cloud into a one-slot mailbox (latest wins:
// a cloud still waiting there when a newer one arrives is dropped and counted). ~reset,
// ~set_pose, initialpose and dynamic_reconfigure answer at once and hand their change to the
// worker, which applies it before the next scan. map -> odom is sent from the manager's
// multi-threaded queue, diagnostics read counters of their own: neither waits for a
// registration.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "cube_scan_matcher/SetPose.h"
#include "cube_scan_matcher/ScanMatcherConfig.h"
#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/chain_covariance.h"
#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/core/pose_covariance.h"
#include "cube_scan_matcher/core/vector6.h"
#include "cube_scan_matcher/ros/nodelet_queues.h"
#include "cube_scan_matcher/ros/params.h"

namespace cube_scan_matcher {

class ScanMatcherNodelet : public nodelet::Nodelet {
 public:
  ScanMatcherNodelet() = default;
  ~ScanMatcherNodelet() override;

 private:
  void onInit() override;
  /// Counts the arrival and puts `msg` into the mailbox; returns at once.
  void cloudCallback(const sensor_msgs::PointCloud2ConstPtr& msg);
  /// The worker thread: runs the posted changes, then registers the mailbox's cloud.
  void workerLoop();
  /// Runs `change` on the worker thread before its next scan.
  void post(std::function<void()> change);
  /// The work on one cloud, on the worker thread; may throw. Its steps, in order:
  void processCloud(const sensor_msgs::PointCloud2& msg, double received_wall);
  /// One scan on its way through processCloud.
  struct Scan {
    Scan(const sensor_msgs::PointCloud2& m, double r, Status& s) : msg(m), received(r), status(s) {}
    const sensor_msgs::PointCloud2& msg;
    double received;  ///< wall time of the callback [s]
    Status& status;   ///< filled along the way, published at the end
    Eigen::Isometry3d T_base_cloud = Eigen::Isometry3d::Identity();
    std::optional<Eigen::Isometry3d> odom;  ///< T_odom_base at the stamp, if tf had it
    PointArray points;                      ///< valid points in base_frame
    std::optional<PointTimes> times;        ///< their times, from the cloud's time_field
    std::optional<std::vector<float>> intensity;  ///< their "intensity" field, if the cloud has one
  };
  /// Input rate and scans dropped before the callback (header.seq gaps; manager thread).
  void countArrival(const sensor_msgs::PointCloud2& msg);
  bool checkHeader(Scan& scan);     ///< a stamp and a frame
  bool trackStamps(Scan& scan);     ///< out of order (dropped) or time going back (reset)
  bool lookupFrames(Scan& scan);    ///< cloud -> base_frame and odometry at the stamp
  bool convertPoints(Scan& scan);   ///< PointCloud2 -> filtered points in base_frame
  OnlineStep registerScan(Scan& scan);  ///< the core: register, gate, chain
  void publishPose(const Scan& scan, const OnlineStep& step);  ///< pose, odometry, path, cloud, tf
  void publishStatus(Scan& scan, GateReason reason, const std::string& message);
  /// The bad-input exit: counted, logged (throttled) and published as BAD_INPUT.
  void rejectInput(Scan& scan, const std::string& why);
  bool resetService(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool setPoseService(SetPose::Request& req, SetPose::Response& res);
  /// RViz's "2D Pose Estimate" (topic initialpose): x, y and yaw restart the chain.
  void initialPoseCallback(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  /// A new chain's start: the pose (T_map_base), the odometry when it held (none: it holds
  /// at the next scan as it is) and its covariance [m², rad²].
  struct ChainStart {
    Eigen::Isometry3d pose;
    std::optional<Eigen::Isometry3d> odom;
    Matrix6d covariance;
  };
  /// ~set_pose and initialpose: `start` set from `pose` (map_frame), or the reason it is
  /// refused. With `stamp_is_approximate` (a pose clicked in RViz, stamped with its clock) a
  /// stamp the odometry cannot be looked up at means "now": the pose holds at the next scan.
  /// Reads no worker state: runs on any thread.
  std::string parseStart(const geometry_msgs::PoseWithCovarianceStamped& pose,
                         const std::string& source, bool stamp_is_approximate,
                         ChainStart& start);
  /// Worker thread: the next scan starts a new chain at `start`.
  void restartChain(const ChainStart& start, const std::string& source);
  /// Worker thread: initialpose merged with the last pose's z, roll and pitch, then restarted.
  void applyInitialPose(const geometry_msgs::PoseWithCovarianceStamped& msg);
  /// Worker thread: ~reset (continuous or not).
  void applyReset();
  void reconfigure(ScanMatcherConfig& config, uint32_t level);
  /// T_target_source at `stamp`, waiting at most ~tf_timeout; nullopt (and counted) on failure.
  std::optional<Eigen::Isometry3d> lookup(const std::string& target, const std::string& source,
                                          const ros::Time& stamp, std::string& error);
  void resetState(const std::string& why);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  // First member, so destroyed last: every handle below goes while its queue still lives.
  NodeletQueues queues_;
  // Written by onInit, then only its matcher settings, by the worker (a reconfigure): other
  // threads read the frames, timeouts and the like, never params_.matcher.
  NodeParams params_;
  std::unique_ptr<OnlineMatcher> matcher_;

  // The mailbox and the posted changes, handed from callbacks to the worker.
  std::mutex inbox_mutex_;
  std::condition_variable inbox_cv_;
  sensor_msgs::PointCloud2ConstPtr inbox_;  // the newest cloud not yet taken
  double inbox_received_ = 0.0;             // its arrival [s, wall]
  std::deque<std::function<void()>> changes_;
  bool stopping_ = false;
  // The settings the last accepted reconfigure asked for (applied or about to be), and the
  // worker's answer to the request the reconfigure callback waits for (inbox_mutex_).
  NodeParams requested_params_;
  std::condition_variable reconfigure_cv_;
  std::uint64_t reconfigure_asked_ = 0, reconfigure_waiting_ = 0, reconfigure_answered_ = 0;
  bool reconfigure_refused_ = false;
  ScanMatcherConfig reconfigure_kept_;
  std::thread worker_;

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  ros::Subscriber cloud_sub_, initialpose_sub_;
  ros::Publisher pose_pub_, odom_pub_, path_pub_, cloud_pub_, status_pub_;
  ros::ServiceServer reset_srv_, set_pose_srv_;
  std::unique_ptr<dynamic_reconfigure::Server<ScanMatcherConfig>> reconfigure_server_;
  boost::recursive_mutex reconfigure_mutex_;  // dynamic_reconfigure needs a boost mutex
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> rate_status_;
  double min_rate_ = 0.0, max_rate_ = 0.0;  // FrequencyStatus keeps references to these
  ros::Timer diagnostics_timer_;

  // map -> odom, sent at once after each scan and re-sent on tf_timer_, stamped
  // now + transform_tolerance (as amcl does) so that lookups at the current time succeed.
  void sendMapOdom();
  void sendMapOdomAt(const ros::Time& stamp);  ///< under tf_mutex_
  std::mutex tf_mutex_;  // guards the two below (the timer must not wait for a registration)
  std::optional<Eigen::Isometry3d> map_odom_;
  std::optional<ros::Time> last_map_odom_stamp_;
  ros::Timer tf_timer_;

  std::unique_ptr<ChainCovariance> chain_;  // the published pose's covariance along the chain
  std::unique_ptr<OdometryAnchor> anchor_;  // role anchored: the chain tied to the odometry
  // The last twist published with an estimate [m/s, rad/s] in base_frame (none at a chain's
  // start): its change to the next one is the motion model's error (twistCovariance).
  std::optional<Vector6d> last_twist_;
  std::optional<Eigen::Isometry3d> last_pose_;  // T_map_base published last (this chain)
  std::optional<Matrix6d> last_covariance_;     // its covariance [m², rad²]
  std::optional<Eigen::Isometry3d> last_odom_;  // T_odom_base at that scan, if known
  // A chain's start given for a time (~set_pose's stamp, a continuous ~reset's last scan): the
  // pose then and the odometry then (none: the pose holds at the next scan as it is).
  struct PendingStart {
    Eigen::Isometry3d pose;
    std::optional<Eigen::Isometry3d> odom;
  };
  std::optional<PendingStart> pending_start_;

  nav_msgs::Path path_;
  std::optional<ros::Time> last_stamp_;
  std::optional<std::uint32_t> last_seq_;  // the manager thread's (countArrival)

  // Counters: written by the worker (dropped_ also by the callback), read by diagnostics.
  std::atomic<std::uint32_t> dropped_{0}, rejected_{0}, tf_failures_{0}, processed_{0};
  std::atomic<std::uint32_t> bad_input_{0}, consecutive_rejections_{0};
  std::atomic<int> max_consecutive_rejections_{0};  // params_.matcher's, for diagnostics
  std::mutex stats_mutex_;
  std::deque<double> latencies_;  // last latencies [s], for diagnostics (stats_mutex_)
  std::atomic<bool> initialised_{false};
  std::string init_error_;
  std::string param_warnings_;  ///< unknown names under ~ (misspelt?): a WARN in diagnostics.
};

}  // namespace cube_scan_matcher
