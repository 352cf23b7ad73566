#include "cube_scan_matcher/ros/sweep_assembler_nodelet.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <iomanip>
#include <sstream>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <pluginlib/class_list_macros.hpp>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2/exceptions.h>

#include "cube_scan_matcher/ros/read_param.h"

namespace cube_scan_matcher {

namespace {

std::string readString(const ros::NodeHandle& pnh, const std::string& name, std::string value) {
  if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
    throw ParamError("parameter ~" + name + " has the wrong type (expected a string)");
  }
  return value;
}

/// Keeps the longest wall time [s] of a callback in `longest` (held under the caller's lock):
/// the assembler runs on the manager's threads, so its calls must stay short.
struct CallTimer {
  explicit CallTimer(double& longest) : longest_(longest) {}
  ~CallTimer() { longest_ = std::max(longest_, (ros::WallTime::now() - begin_).toSec()); }
  CallTimer(const CallTimer&) = delete;
  CallTimer& operator=(const CallTimer&) = delete;

 private:
  double& longest_;
  const ros::WallTime begin_ = ros::WallTime::now();
};

/// Rotation angle [rad] of R about axis 0, 1, 2 (x, y, z): exact when R is a rotation about
/// that axis only.
double angleAbout(const Eigen::Matrix3d& R, int axis) {
  switch (axis) {
    case 0: return std::atan2(R(2, 1), R(2, 2));
    case 1: return std::atan2(R(0, 2), R(0, 0));
    default: return std::atan2(R(1, 0), R(0, 0));
  }
}

}  // namespace

const std::vector<std::string>& knownAssemblerParamNames() {
  static const std::vector<std::string> names = {
      "fixed_frame",  "tilt_reference_frame", "tilt_axis", "turn_hysteresis", "sweep_duration",
      "stall_timeout", "max_line_gap",        "min_lines", "max_lines",       "tf_timeout",
      "range_min",     "range_max",           "queue_size",
      "num_worker_threads"};  // the stand-alone node's nodelet::Loader reads it here
  return names;
}

AssemblerParams loadAssemblerParams(const ros::NodeHandle& pnh) {
  AssemblerParams p;
  p.fixed_frame = readString(pnh, "fixed_frame", p.fixed_frame);
  if (p.fixed_frame.empty()) throw ParamError("parameter ~fixed_frame must not be empty");
  p.tilt_reference_frame = readString(pnh, "tilt_reference_frame", p.tilt_reference_frame);
  const std::string axis = readString(pnh, "tilt_axis", "x");
  if (axis != "x" && axis != "y" && axis != "z") {
    throw ParamError("parameter ~tilt_axis = '" + axis + "' must be x, y or z");
  }
  p.tilt_axis = axis[0] - 'x';
  SweepCutterSettings& c = p.cutter;
  c.turn_hysteresis = readParam(pnh, "turn_hysteresis", c.turn_hysteresis, 0.0, 1.0, "rad");
  c.sweep_duration = readParam(pnh, "sweep_duration", c.sweep_duration, 0.0, 3600.0, "s");
  c.stall_timeout = readParam(pnh, "stall_timeout", c.stall_timeout, 0.0, 3600.0, "s");
  c.max_line_gap = readParam(pnh, "max_line_gap", c.max_line_gap, 0.001, 60.0, "s");
  c.min_lines = readParam(pnh, "min_lines", c.min_lines, 1, 1000000, "lines");
  c.max_lines = readParam(pnh, "max_lines", c.max_lines, 1, 1000000, "lines");
  if (c.max_lines < c.min_lines) {
    throw ParamError("parameter ~max_lines = " + std::to_string(c.max_lines) +
                     " must be >= ~min_lines = " + std::to_string(c.min_lines));
  }
  if (p.tilt_reference_frame.empty() && c.sweep_duration <= 0.0) {
    throw ParamError(
        "parameter ~sweep_duration must be > 0 when ~tilt_reference_frame is empty (without a "
        "tilt angle the sweep duration is the only cut)");
  }
  p.tf_timeout = readParam(pnh, "tf_timeout", p.tf_timeout, 0.0, 10.0, "s");
  p.range_min = readParam(pnh, "range_min", p.range_min, 0.0, 1e4, "m");
  p.range_max = readParam(pnh, "range_max", p.range_max, 0.0, 1e6, "m");
  if (p.range_max > 0.0 && p.range_min >= p.range_max) {
    throw ParamError("parameter ~range_min must be below ~range_max (0 = the scan's own)");
  }
  p.queue_size = readParam(pnh, "queue_size", p.queue_size, 1, 10000, "lines");
  try {
    validate(p.cutter);
  } catch (const std::invalid_argument& e) {
    throw ParamError(e.what());
  }
  return p;
}

SweepAssemblerNodelet::~SweepAssemblerNodelet() {
  queue_timer_.stop();
  diagnostics_timer_.stop();
  scan_sub_.shutdown();
  if (!initialised_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  NODELET_INFO(
      "SweepAssemblerNodelet: %lu lines received, %lu lost before the callback, %lu dropped "
      "without tf, %lu late, %lu while the tilt was stalled, %lu bad, %lu in discarded sweeps; "
      "%lu sweeps published (%lu points), %lu discarded; %lu time resets; %zu lines left in the "
      "current sweep, %zu waiting for tf; longest callback %.1f ms",
      (unsigned long)lines_received_, (unsigned long)lines_lost_, (unsigned long)lines_dropped_tf_,
      (unsigned long)lines_late_, (unsigned long)lines_stalled_, (unsigned long)lines_bad_,
      (unsigned long)lines_in_discarded_sweeps_, (unsigned long)sweeps_published_,
      (unsigned long)points_published_, (unsigned long)sweeps_discarded_,
      (unsigned long)time_resets_, pending_.size(), waiting_.size(), 1e3 * longest_call_s_);
}

void SweepAssemblerNodelet::onInit() {
  queues_.hold(getSTCallbackQueue(), getMTCallbackQueue());
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& pnh = getPrivateNodeHandle();
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, getName());
  updater_->setHardwareID("none");
  updater_->add("sweep assembly", this, &SweepAssemblerNodelet::diagnose);
  // force_update: update() skips a tick that comes a little early, and stays silent after a
  // bag loop until the (simulated) clock is back where it was.
  diagnostics_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) {
    updater_->force_update();
  });
  try {
    params_ = loadAssemblerParams(pnh);
  } catch (const std::exception& e) {
    // Refuse to start, but never take the manager (and its other nodelets) down.
    init_error_ = e.what();
    NODELET_ERROR("%s. SweepAssemblerNodelet is NOT running: fix the parameter and restart it.",
                  e.what());
    return;
  }
  param_warnings_ = unknownParamReport(pnh, knownAssemblerParamNames());
  if (!param_warnings_.empty()) NODELET_WARN("%s", param_warnings_.c_str());
  cutter_ = std::make_unique<SweepCutter>(params_.cutter);
  // tf is kept 30 s: far more than any line waits (tf_timeout <= 10 s).
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(30.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("assembled_cloud", 2);
  queue_timer_ = nh.createTimer(ros::Duration(0.05), [this](const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const CallTimer timer(longest_call_s_);
    try {
      processQueue();
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "waiting lines not processed: %s", e.what());
    }
  });
  initialised_ = true;
  // Subscribe last: callbacks may start at once.
  scan_sub_ = nh.subscribe("scan", std::uint32_t(params_.queue_size),
                           &SweepAssemblerNodelet::scanCallback, this);
  std::ostringstream cuts;
  if (!params_.tilt_reference_frame.empty()) {
    cuts << "at turning points of the tilt about " << char('x' + params_.tilt_axis) << " of "
         << params_.tilt_reference_frame;
    if (params_.cutter.sweep_duration > 0.0) cuts << " or ";
  }
  if (params_.cutter.sweep_duration > 0.0) {
    cuts << "every " << params_.cutter.sweep_duration << " s";
  }
  NODELET_INFO("SweepAssemblerNodelet: lines from %s assembled in %s, cut %s, to %s",
               scan_sub_.getTopic().c_str(), params_.fixed_frame.c_str(), cuts.str().c_str(),
               cloud_pub_.getTopic().c_str());
}

void SweepAssemblerNodelet::scanCallback(const sensor_msgs::LaserScanConstPtr& msg) {
  if (!initialised_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const CallTimer timer(longest_call_s_);
  try {
    ++lines_received_;
    // Lines the subscriber queue dropped never reach this callback: counted from seq gaps.
    const std::uint32_t seq = msg->header.seq;
    if (last_seq_ && seq > *last_seq_ + 1) {
      const std::uint32_t gap = std::min<std::uint32_t>(seq - *last_seq_ - 1, 100000);
      lines_lost_ += gap;
      NODELET_WARN_THROTTLE(5.0, "%u lines lost before the callback (seq %u -> %u): raise queue_size",
                            gap, *last_seq_, seq);
    }
    last_seq_ = seq;
    const ros::Time stamp = msg->header.stamp;
    if (stamp.isZero() || msg->header.frame_id.empty() || !std::isfinite(msg->time_increment)) {
      ++lines_bad_;
      NODELET_ERROR_THROTTLE(5.0, "line %u not used: %s", seq,
                             stamp.isZero() ? "zero stamp (tf cannot be looked up at it)"
                             : msg->header.frame_id.empty() ? "empty frame_id"
                                                             : "time_increment is not finite");
      return;
    }
    const double gap = params_.cutter.max_line_gap;
    if (newest_arrival_stamp_ && stamp + ros::Duration(gap) < *newest_arrival_stamp_) {
      // Time went backwards (a bag loop, a clock reset). The lines still waiting belong to the
      // old time line: those whose tf is there are used, the rest dropped; the tf buffer, full
      // of later stamps, is cleared (it would refuse the new, older tf). The cutter closes the
      // current sweep when it sees this line.
      ++time_resets_;
      NODELET_WARN("time went backwards from %.3f s to %.3f s (bag loop or clock reset): the "
                   "current sweep is closed and the tf buffer cleared",
                   newest_arrival_stamp_->toSec(), stamp.toSec());
      processQueue();
      for (const Waiting& w : waiting_) dropWaiting(w, "time went backwards before its tf came");
      waiting_.clear();
      tf_buffer_->clear();
      tilt_origin_.reset();
      newest_arrival_stamp_ = stamp;
    } else if (!newest_arrival_stamp_ || stamp > *newest_arrival_stamp_) {
      newest_arrival_stamp_ = stamp;
    }
    // Waiting lines are kept sorted by stamp: a line that arrives before an older one has been
    // used takes its place in time.
    auto it = waiting_.end();
    while (it != waiting_.begin() && std::prev(it)->scan->header.stamp > stamp) --it;
    waiting_.insert(it, Waiting{msg, ros::Time::now()});
    processQueue();
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "line %u not processed: %s", msg->header.seq, e.what());
  }
}

bool SweepAssemblerNodelet::transformable(const sensor_msgs::LaserScan& scan,
                                          std::string& error) const {
  // laser_geometry looks tf up at the first and the last beam's time.
  const ros::Time start = scan.header.stamp;
  const double span =
      scan.ranges.empty() ? 0.0 : double(scan.ranges.size() - 1) * double(scan.time_increment);
  const ros::Time end = start + ros::Duration(span);
  const std::string& frame = scan.header.frame_id;
  return tf_buffer_->canTransform(params_.fixed_frame, frame, start, &error) &&
         tf_buffer_->canTransform(params_.fixed_frame, frame, end, &error) &&
         (params_.tilt_reference_frame.empty() ||
          tf_buffer_->canTransform(params_.tilt_reference_frame, frame, start, &error));
}

void SweepAssemblerNodelet::dropWaiting(const Waiting& w, const std::string& why) {
  ++lines_dropped_tf_;
  NODELET_WARN_THROTTLE(
      5.0, "line at %.3f s in %s dropped (%lu so far): no tf to %s%s%s within tf_timeout = %.2f s: %s",
      w.scan->header.stamp.toSec(), w.scan->header.frame_id.c_str(),
      (unsigned long)lines_dropped_tf_, params_.fixed_frame.c_str(),
      params_.tilt_reference_frame.empty() ? "" : " and ",
      params_.tilt_reference_frame.c_str(), params_.tf_timeout, why.c_str());
}

void SweepAssemblerNodelet::processQueue() {
  if (!initialised_) return;
  const ros::Time now = ros::Time::now();
  while (!waiting_.empty()) {
    Waiting& w = waiting_.front();
    if (now < w.arrival) w.arrival = now;  // the clock jumped back: the wait starts again
    std::string error;
    if (transformable(*w.scan, error)) {
      const sensor_msgs::LaserScanConstPtr scan = w.scan;
      waiting_.pop_front();
      try {
        useLine(*scan);
      } catch (const tf2::TransformException& e) {
        dropWaiting(Waiting{scan, now}, e.what());
      } catch (const std::exception& e) {
        ++lines_bad_;
        NODELET_ERROR_THROTTLE(5.0, "line at %.3f s not used: %s", scan->header.stamp.toSec(),
                               e.what());
      }
      continue;
    }
    if ((now - w.arrival).toSec() >= params_.tf_timeout) {
      dropWaiting(w, error.empty() ? "no transform" : error);
      waiting_.pop_front();
      continue;
    }
    break;  // it may still come; the later lines wait behind it (their order is kept)
  }
}

std::optional<double> SweepAssemblerNodelet::tiltAngle(const sensor_msgs::LaserScan& scan) {
  if (params_.tilt_reference_frame.empty()) return std::nullopt;
  const geometry_msgs::TransformStamped t = tf_buffer_->lookupTransform(
      params_.tilt_reference_frame, scan.header.frame_id, scan.header.stamp);
  const auto& q = t.transform.rotation;
  const Eigen::Matrix3d R = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  // Measured from the first line's rotation: R * R0^T is a rotation about the joint's axis
  // even when the scan frame is mounted with a fixed rotation behind the joint.
  if (!tilt_origin_) tilt_origin_ = R;
  return angleAbout(R * tilt_origin_->transpose(), params_.tilt_axis);
}

void SweepAssemblerNodelet::useLine(const sensor_msgs::LaserScan& in) {
  sensor_msgs::LaserScan scan = in;
  if (!scan.intensities.empty() && scan.intensities.size() != scan.ranges.size()) {
    NODELET_WARN_THROTTLE(5.0, "line at %.3f s has %zu intensities for %zu ranges: its intensities "
                          "are ignored", scan.header.stamp.toSec(), scan.intensities.size(),
                          scan.ranges.size());
    scan.intensities.clear();
  }
  // Kept beams: max(range_min, scan.range_min) <= r < min(range_max, scan.range_max), as
  // laser_geometry keeps them (0 = the scan's own limit).
  if (params_.range_min > scan.range_min) scan.range_min = float(params_.range_min);
  const double cutoff =
      params_.range_max > 0.0 ? std::min(params_.range_max, double(scan.range_max)) : -1.0;
  const std::optional<double> angle = tiltAngle(scan);  // may throw tf2::TransformException

  sensor_msgs::PointCloud2 cloud;
  projector_.transformLaserScanToPointCloud(
      params_.fixed_frame, scan, cloud, *tf_buffer_, cutoff,
      laser_geometry::channel_option::Intensity | laser_geometry::channel_option::Index);

  Line line;
  line.stamp = scan.header.stamp;
  const double increment = scan.time_increment;
  const double span = scan.ranges.empty() ? 0.0 : double(scan.ranges.size() - 1) * increment;
  line.end = scan.header.stamp + ros::Duration(std::max(0.0, span));
  line.has_intensity = !scan.intensities.empty();
  line.beams.reserve(cloud.width);
  if (cloud.width > 0) {
    sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
    sensor_msgs::PointCloud2ConstIterator<std::int32_t> index(cloud, "index");
    std::optional<sensor_msgs::PointCloud2ConstIterator<float>> intensity;
    if (line.has_intensity) intensity.emplace(cloud, "intensity");
    for (std::uint32_t i = 0; i < cloud.width; ++i, ++x, ++y, ++z, ++index) {
      Beam b{*x, *y, *z, intensity ? **intensity : 0.0f, double(*index) * increment};
      if (intensity) ++*intensity;
      // laser_geometry keeps finite ranges only; a NaN here would come from tf.
      if (std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z)) line.beams.push_back(b);
    }
    // Beams in time order (a negative time_increment scans backwards).
    if (increment < 0.0) std::reverse(line.beams.begin(), line.beams.end());
  }
  const CutResult r = cutter_->addLine(scan.header.stamp.toSec(), angle);
  applyCut(r, std::move(line), scan);
}

void SweepAssemblerNodelet::applyCut(const CutResult& r, Line&& line,
                                     const sensor_msgs::LaserScan& scan) {
  if (r.line_kept) pending_.push_back(std::move(line));
  if (r.reason == CutReason::Stall) {
    // Named with the axis and frame it is measured about: a laser that nods about another
    // axis (tilt_axis x while it pitches about y) looks stalled too.
    NODELET_WARN("the tilt about %c (tilt_axis) of the laser in '%s' (tilt_reference_frame) has "
                 "not moved by more than turn_hysteresis = %.4f rad for stall_timeout = %.2f s "
                 "(line at %.3f s): sweep closed; lines are discarded until it moves again. If "
                 "the laser is moving, check tilt_axis and tilt_reference_frame",
                 char('x' + params_.tilt_axis), params_.tilt_reference_frame.c_str(),
                 params_.cutter.turn_hysteresis, params_.cutter.stall_timeout,
                 scan.header.stamp.toSec());
  }
  if (r.event == CutEvent::SweepEnded) {
    publishSweep(r.closed_lines, r.reason);
  } else if (r.event == CutEvent::Discarded) {
    if (r.closed_lines > 0) {
      pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(r.closed_lines));
      ++sweeps_discarded_;
      lines_in_discarded_sweeps_ += r.closed_lines;
      NODELET_WARN_THROTTLE(5.0, "sweep of %zu lines discarded (closed by: %s): fewer than "
                            "min_lines = %d", r.closed_lines, toString(r.reason).c_str(),
                            params_.cutter.min_lines);
    }
    if (!r.line_kept && r.reason == CutReason::LateLine) {
      ++lines_late_;
      NODELET_WARN_THROTTLE(5.0, "line at %.3f s arrived after a newer line was used: dropped "
                            "(%lu late lines so far)", scan.header.stamp.toSec(),
                            (unsigned long)lines_late_);
    } else if (!r.line_kept && r.reason == CutReason::Stalled) {
      ++lines_stalled_;
    }
  }
  if (was_stalled_ && !cutter_->stalled()) {
    NODELET_INFO("the tilt moves again (line at %.3f s): a new sweep starts; %lu lines were "
                 "discarded while it was stalled", scan.header.stamp.toSec(),
                 (unsigned long)lines_stalled_);
  }
  was_stalled_ = cutter_->stalled();
  if (pending_.size() != cutter_->pendingLines()) {  // a bug: say so, and start afresh
    NODELET_ERROR("sweep lines out of step with the cutter (%zu, %zu): both reset",
                  pending_.size(), cutter_->pendingLines());
    pending_.clear();
    cutter_->reset();
  }
}

void SweepAssemblerNodelet::publishSweep(std::size_t lines, CutReason reason) {
  // The reference time: the last beam of the sweep's last line (lines are in time order).
  ros::Time reference = pending_[lines - 1].end;
  bool intensity = true;
  std::size_t n = 0;
  for (std::size_t k = 0; k < lines; ++k) {
    reference = std::max(reference, pending_[k].end);
    intensity = intensity && pending_[k].has_intensity;
    n += pending_[k].beams.size();
  }
  struct Point {
    float x, y, z, intensity, time;
  };
  std::vector<Point> points;
  points.reserve(n);
  for (std::size_t k = 0; k < lines; ++k) {
    const double line_offset = (pending_[k].stamp - reference).toSec();
    for (const Beam& b : pending_[k].beams) {
      points.push_back({b.x, b.y, b.z, b.intensity, float(line_offset + b.time)});
    }
  }
  const double first_line = (pending_.front().stamp - reference).toSec();
  pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(lines));
  // Never a time going backwards within a cloud (overlapping lines would need it).
  auto earlier = [](const Point& a, const Point& b) { return a.time < b.time; };
  if (!std::is_sorted(points.begin(), points.end(), earlier)) {
    std::stable_sort(points.begin(), points.end(), earlier);
  }

  // Published by value: roscpp serialises it even for a subscriber in the same manager (one
  // copy of the sweep), and numbers header.seq, from which the matcher counts the sweeps its
  // queue dropped.
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = params_.fixed_frame;
  cloud.header.stamp = reference;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  if (intensity) {
    modifier.setPointCloud2Fields(5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                                  sensor_msgs::PointField::FLOAT32, "z", 1,
                                  sensor_msgs::PointField::FLOAT32, "intensity", 1,
                                  sensor_msgs::PointField::FLOAT32, "time", 1,
                                  sensor_msgs::PointField::FLOAT32);
  } else {
    modifier.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                                  sensor_msgs::PointField::FLOAT32, "z", 1,
                                  sensor_msgs::PointField::FLOAT32, "time", 1,
                                  sensor_msgs::PointField::FLOAT32);
  }
  modifier.resize(points.size());
  cloud.height = 1;
  cloud.width = std::uint32_t(points.size());
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  std::uint8_t* out = cloud.data.data();
  for (const Point& p : points) {
    const float values[5] = {p.x, p.y, p.z, p.intensity, p.time};
    if (intensity) {
      std::memcpy(out, values, 5 * sizeof(float));
    } else {
      std::memcpy(out, values, 3 * sizeof(float));
      std::memcpy(out + 12, &p.time, sizeof(float));
    }
    out += cloud.point_step;
  }
  ++sweeps_published_;
  points_published_ += points.size();
  NODELET_DEBUG("sweep %lu: %zu lines, %zu points, %.3f s long, ends at %.3f s (%s)",
                (unsigned long)sweeps_published_, lines, points.size(), -first_line,
                reference.toSec(), toString(reason).c_str());
  cloud_pub_.publish(cloud);
}

void SweepAssemblerNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  using diagnostic_msgs::DiagnosticStatus;
  if (!init_error_.empty()) {
    stat.summary(DiagnosticStatus::ERROR, "not running: " + init_error_);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  stat.add("lines received", lines_received_);
  stat.add("lines lost before the callback", lines_lost_);
  stat.add("lines dropped without tf", lines_dropped_tf_);
  stat.add("lines late", lines_late_);
  stat.add("lines discarded while stalled", lines_stalled_);
  stat.add("bad lines", lines_bad_);
  stat.add("lines in discarded sweeps", lines_in_discarded_sweeps_);
  stat.add("sweeps published", sweeps_published_);
  stat.add("sweeps discarded", sweeps_discarded_);
  stat.add("points published", points_published_);
  stat.add("time resets", time_resets_);
  stat.add("lines in the current sweep", pending_.size());
  stat.add("lines waiting for tf", waiting_.size());
  stat.add("tilt stalled", was_stalled_);
  stat.add("longest callback [s]", longest_call_s_);
  if (was_stalled_) {
    stat.summary(DiagnosticStatus::WARN,
                 std::string("tilt stalled: lines are discarded (no motion about tilt_axis ") +
                     char('x' + params_.tilt_axis) + " of '" + params_.tilt_reference_frame +
                     "' (tilt_reference_frame): if the laser moves, check both)");
  } else if (lines_dropped_tf_ + lines_lost_ + lines_late_ + lines_bad_ + sweeps_discarded_ > 0) {
    stat.summary(DiagnosticStatus::WARN, "some lines dropped or sweeps discarded");
  } else {
    stat.summary(DiagnosticStatus::OK, sweeps_published_ ? "assembling" : "waiting for a sweep");
  }
  if (!param_warnings_.empty()) {
    stat.add("unknown parameters", param_warnings_);
    stat.mergeSummary(DiagnosticStatus::WARN, "unknown parameters (misspelt?)");
  }
}

}  // namespace cube_scan_matcher

PLUGINLIB_EXPORT_CLASS(cube_scan_matcher::SweepAssemblerNodelet, nodelet::Nodelet)
