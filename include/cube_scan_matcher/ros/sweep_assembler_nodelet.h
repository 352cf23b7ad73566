// SweepAssemblerNodelet: assembles the lines (sensor_msgs/LaserScan) of a tilting 2D laser into
// one sensor_msgs/PointCloud2 per sweep in a fixed frame (laser_assembler is not in
// Debian). Each line is projected with laser_geometry into fixed_frame, each beam placed
// by the tf at its own time (laser_geometry interpolates between the transforms at the line's
// first and last beam); lines whose tf has not arrived yet wait up to tf_timeout. Where a sweep
// ends is decided by assembly/sweep_cutter.h from the tilt angle (the scan frame's rotation
// relative to tilt_reference_frame about tilt_axis) or by duration. Topics, parameters and the
// cloud's layout: README.md, "Sweep assembler", and docs/method.md.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <diagnostic_updater/diagnostic_updater.h>
#include <laser_geometry/laser_geometry.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "cube_scan_matcher/assembly/sweep_cutter.h"
#include "cube_scan_matcher/ros/nodelet_queues.h"

namespace cube_scan_matcher {

/// Every parameter of SweepAssemblerNodelet (config/sweep_assembler.yaml, docs/parameters.md).
struct AssemblerParams {
  std::string fixed_frame = "odom";  ///< frame of the assembled clouds; fixed in the world.
  /// The mount frame the tilt is measured against; empty = no tilt (duration mode only).
  std::string tilt_reference_frame;
  int tilt_axis = 0;              ///< 0, 1, 2: x, y, z of tilt_reference_frame ("x", "y", "z").
  SweepCutterSettings cutter;     ///< turn_hysteresis [rad], sweep_duration, stall_timeout,
                                  ///< max_line_gap [s], min_lines, max_lines.
  double tf_timeout = 0.5;        ///< [s] (ROS time) a line waits this long for its tf, [0, 10].
  double range_min = 0.0;         ///< [m] beams shorter are dropped; 0 = the scan's range_min.
  double range_max = 0.0;         ///< [m] beams this long or longer are dropped; 0 = the scan's.
  int queue_size = 100;           ///< subscriber queue [lines], [1, 10000].
};

/// Reads and validates every parameter from the private node handle; throws ParamError
/// (ros/params.h) naming the first bad one.
AssemblerParams loadAssemblerParams(const ros::NodeHandle& pnh);

/// Every parameter name loadAssemblerParams reads: others under ~ are warned about.
const std::vector<std::string>& knownAssemblerParamNames();

class SweepAssemblerNodelet : public nodelet::Nodelet {
 public:
  SweepAssemblerNodelet() = default;
  ~SweepAssemblerNodelet() override;

 private:
  /// One line waiting for its tf.
  struct Waiting {
    sensor_msgs::LaserScanConstPtr scan;
    ros::Time arrival;  ///< ROS time of the callback
  };
  /// One beam of a projected line, in fixed_frame.
  struct Beam {
    float x, y, z, intensity;
    double time;  ///< [s] after the line's stamp (index * time_increment)
  };
  /// One projected line of the current sweep.
  struct Line {
    ros::Time stamp;  ///< the first beam's time
    ros::Time end;    ///< the last beam's time (the latest, if time_increment < 0)
    std::vector<Beam> beams;  ///< the valid beams, in time order
    bool has_intensity = false;
  };

  void onInit() override;
  void scanCallback(const sensor_msgs::LaserScanConstPtr& msg);
  /// Uses the waiting lines, oldest first, whose tf is there; drops those that waited more
  /// than tf_timeout. Stops at the first line that may still wait (keeps the order).
  void processQueue();
  /// True when every transform the line needs is in the buffer; else `error` says which.
  bool transformable(const sensor_msgs::LaserScan& scan, std::string& error) const;
  /// Projects the line, gets its tilt angle and passes it to the cutter.
  void useLine(const sensor_msgs::LaserScan& scan);
  std::optional<double> tiltAngle(const sensor_msgs::LaserScan& scan);
  void applyCut(const CutResult& r, Line&& line, const sensor_msgs::LaserScan& scan);
  /// Publishes the oldest `lines` lines of pending_ as one cloud and removes them.
  void publishSweep(std::size_t lines, CutReason reason);
  void dropWaiting(const Waiting& w, const std::string& why);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  // First member, so destroyed last: every handle below goes while its queue still lives.
  NodeletQueues queues_;
  AssemblerParams params_;
  std::unique_ptr<SweepCutter> cutter_;
  laser_geometry::LaserProjection projector_;
  std::mutex mutex_;  // guards everything below: the callback and the timer may run at once

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber scan_sub_;
  ros::Publisher cloud_pub_;
  ros::Timer queue_timer_, diagnostics_timer_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;

  std::deque<Waiting> waiting_;  ///< sorted by stamp
  std::deque<Line> pending_;     ///< the current sweep, in step with cutter_->pendingLines()
  std::optional<ros::Time> newest_arrival_stamp_;
  std::optional<std::uint32_t> last_seq_;
  std::optional<Eigen::Matrix3d> tilt_origin_;  ///< rotation at the first line (angle 0)
  bool was_stalled_ = false;

  // Counters (since start), logged at shutdown and in the diagnostics.
  double longest_call_s_ = 0.0;  // [s] wall time of the longest line callback or queue tick
  std::uint64_t lines_received_ = 0, lines_lost_ = 0, lines_dropped_tf_ = 0, lines_bad_ = 0;
  std::uint64_t lines_late_ = 0, lines_stalled_ = 0, lines_in_discarded_sweeps_ = 0;
  std::uint64_t sweeps_published_ = 0, sweeps_discarded_ = 0, time_resets_ = 0;
  std::uint64_t points_published_ = 0;
  bool initialised_ = false;
  std::string init_error_;
  std::string param_warnings_;  ///< unknown names under ~ (misspelt?): a WARN in diagnostics.
};

}  // namespace cube_scan_matcher
