#include "cube_scan_matcher/ros/scan_matcher_nodelet.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <pluginlib/class_list_macros.hpp>
#include <tf2_eigen/tf2_eigen.h>

#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/simd_path.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/transforms.h"

namespace cube_scan_matcher {
namespace {

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& T) { return tf2::toMsg(T); }

/// A covariance in PoseWithCovariance's and TwistWithCovariance's row-major order
/// [x y z, rotation about x y z].
boost::array<double, 36> toMsg(const Matrix6d& c) {
  boost::array<double, 36> m{};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) m[std::size_t(6 * i + j)] = c(i, j);
  }
  return m;
}

/// A twist [vx vy vz, wx wy wz] [m/s, rad/s] as a message.
geometry_msgs::Twist toTwistMsg(const Vector6d& v) {
  geometry_msgs::Twist t;
  t.linear.x = v(0), t.linear.y = v(1), t.linear.z = v(2);
  t.angular.x = v(3), t.angular.y = v(4), t.angular.z = v(5);
  return t;
}

}  // namespace

ScanMatcherNodelet::~ScanMatcherNodelet() {
  // Stop every source of callbacks before any member goes: members are destroyed in reverse
  // order, so with the default destructor a timer or cloud callback already queued could run
  // on a manager thread against members destroyed before its handle. Each stop waits for a
  // callback of its own that is running (roscpp's removeByID).
  tf_timer_.stop();
  diagnostics_timer_.stop();
  cloud_sub_.shutdown();
  reset_srv_.shutdown();
  set_pose_srv_.shutdown();
  initialpose_sub_.shutdown();
  // The worker finishes the scan it is on (a registration is not interrupted), then stops;
  // it may still touch the reconfigure server, so it goes first.
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    stopping_ = true;
  }
  inbox_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  reconfigure_server_.reset();
}

void ScanMatcherNodelet::onInit() {
  queues_.hold(getSTCallbackQueue(), getMTCallbackQueue());
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& pnh = getPrivateNodeHandle();
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, getName());
  updater_->setHardwareID("none");
  updater_->add("registration", this, &ScanMatcherNodelet::diagnose);
  // force_update: update() publishes only once its own period has passed since the last
  // time (ROS time), so a timer tick that comes a little early is skipped (a 2 s gap), and
  // after a bag loop it stays silent until the clock is back where it was.
  diagnostics_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) {
    updater_->force_update();
  });
  try {
    params_ = loadParams(pnh);
  } catch (const std::exception& e) {
    // Refuse to start, but never take the manager (and its other nodelets) down.
    init_error_ = e.what();
    NODELET_FATAL("%s. ScanMatcherNodelet is NOT running: fix the parameter and restart it.",
                  e.what());
    return;
  }
  param_warnings_ = unknownParamReport(pnh, knownParamNames());
  if (!param_warnings_.empty()) NODELET_WARN("%s", param_warnings_.c_str());
  matcher_ = std::make_unique<OnlineMatcher>(params_.matcher);
  chain_ = std::make_unique<ChainCovariance>(params_.chain);
  anchor_ = std::make_unique<OdometryAnchor>(params_.anchor);
  requested_params_ = params_;
  max_consecutive_rejections_ = params_.matcher.max_consecutive_rejections;

  min_rate_ = params_.min_rate;
  max_rate_ = params_.max_rate;
  rate_status_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.1, 10), "input rate");
  updater_->add(*rate_status_);

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(60.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  if (params_.publishesTf()) {
    tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    // On the manager's multi-threaded queue: a registration (seconds for a de-skewed sweep)
    // must not hold map -> odom back (sendMapOdom takes tf_mutex_ only).
    tf_timer_ = getMTNodeHandle().createTimer(ros::Duration(1.0 / params_.tf_rate),
                                              [this](const ros::TimerEvent&) { sendMapOdom(); });
  }

  pose_pub_ = pnh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10);
  odom_pub_ = pnh.advertise<nav_msgs::Odometry>("odometry", 10);
  path_pub_ = pnh.advertise<nav_msgs::Path>("path", 1, true);
  cloud_pub_ = pnh.advertise<sensor_msgs::PointCloud2>("registered_cloud", 2);
  status_pub_ = pnh.advertise<Status>("status", 10);
  reset_srv_ = pnh.advertiseService("reset", &ScanMatcherNodelet::resetService, this);
  set_pose_srv_ = pnh.advertiseService("set_pose", &ScanMatcherNodelet::setPoseService, this);

  // The worker before the reconfigure server, whose first callback posts to it. From here on
  // params_.matcher is the worker's.
  const double cube_edge = params_.matcher.registration.grid.cube_edge;
  worker_ = std::thread([this] { workerLoop(); });
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<ScanMatcherConfig>>(reconfigure_mutex_, pnh);
  reconfigure_server_->updateConfig(toConfig(params_));
  reconfigure_server_->setCallback(
      [this](ScanMatcherConfig& c, uint32_t level) { reconfigure(c, level); });

  path_.header.frame_id = params_.map_frame;
  initialised_ = true;
  // Subscribe last: callbacks may start at once.
  cloud_sub_ = nh.subscribe("cloud", std::uint32_t(params_.queue_size),
                            &ScanMatcherNodelet::cloudCallback, this);
  initialpose_sub_ = nh.subscribe("initialpose", 1, &ScanMatcherNodelet::initialPoseCallback, this);
  NODELET_INFO(
      "ScanMatcherNodelet: registering %s in %s (odometry %s, poses in %s), E = %.2f m, "
      "SIMD path %s",
      cloud_sub_.getTopic().c_str(), params_.base_frame.c_str(),
      params_.hasOdometry() ? params_.odom_frame.c_str() : "none: predicted",
      params_.map_frame.c_str(), cube_edge, simdReport().c_str());
}

void ScanMatcherNodelet::reconfigure(ScanMatcherConfig& config, uint32_t /*level*/) {
  // Checked here against the settings asked for last, applied by the worker: a request that
  // is invalid, or whose grids cannot be built (the matcher builds the current reference with
  // it first), leaves every setting as it was. The reply waits for the worker at most 50 ms:
  // when it is idle a refusal carries the old values back in the reply, otherwise in a config
  // update once the worker has tried.
  NodeParams requested;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    requested = requested_params_;
  }
  try {
    applyConfig(config, requested);
  } catch (const std::exception& e) {
    NODELET_WARN("dynamic_reconfigure request refused, settings unchanged: %s", e.what());
    config = toConfig(requested);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    requested_params_ = requested;
  }
  std::uint64_t id;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    id = ++reconfigure_asked_;
    reconfigure_waiting_ = id;
  }
  post([this, id, settings = requested.matcher] {
    bool refused = false;
    try {
      matcher_->setSettings(settings);
      params_.matcher = settings;
      max_consecutive_rejections_ = settings.max_consecutive_rejections;
    } catch (const std::exception& e) {
      refused = true;
      NODELET_WARN("dynamic_reconfigure request refused, settings unchanged: %s", e.what());
    }
    bool late;
    {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      if (refused) requested_params_.matcher = params_.matcher;
      late = reconfigure_waiting_ != id;  // the reply has gone out with the request's values
      reconfigure_answered_ = id;
      reconfigure_refused_ = refused;
      reconfigure_kept_ = toConfig(params_);
    }
    reconfigure_cv_.notify_all();
    if (refused && late) reconfigure_server_->updateConfig(toConfig(params_));
  });
  std::unique_lock<std::mutex> lock(inbox_mutex_);
  reconfigure_cv_.wait_for(lock, std::chrono::milliseconds(50),
                           [&] { return reconfigure_answered_ == id; });
  reconfigure_waiting_ = 0;
  if (reconfigure_answered_ == id && reconfigure_refused_) config = reconfigure_kept_;
}

bool ScanMatcherNodelet::resetService(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  post([this] { applyReset(); });
  res.success = true;
  res.message = "the next scan starts a new chain (reference, pose chain, path and counters reset)";
  if (params_.reset_continuous) res.message += "; it continues from the last pose";
  return true;
}

void ScanMatcherNodelet::applyReset() {
  // Continuous: the new chain starts where the old one was, moved on by the odometry from the
  // last published scan to the next one, so that map does not jump.
  // Its covariance goes on too: the new chain is known no better than the old one's end.
  const std::optional<Eigen::Isometry3d> last_pose = last_pose_, last_odom = last_odom_;
  const std::optional<Matrix6d> last_covariance = last_covariance_;
  resetState("reset requested through the ~reset service");
  if (params_.reset_continuous && last_pose) {
    matcher_->restartAt(*last_pose);
    pending_start_ = PendingStart{*last_pose, last_odom};
    chain_->restart(last_covariance);
    anchor_->reset(last_covariance);
  }
}

bool ScanMatcherNodelet::setPoseService(SetPose::Request& req, SetPose::Response& res) {
  ChainStart start;
  const std::string refused = parseStart(req.pose, "~set_pose", false, start);
  res.success = refused.empty();
  res.message = res.success ? "the next scan starts a new chain at the given pose" : refused;
  if (res.success) {
    post([this, start] { restartChain(start, "~set_pose"); });
  } else {
    NODELET_WARN("~set_pose refused: %s", refused.c_str());
  }
  return true;
}

void ScanMatcherNodelet::initialPoseCallback(
    const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  post([this, msg] { applyInitialPose(*msg); });
}

void ScanMatcherNodelet::applyInitialPose(const geometry_msgs::PoseWithCovarianceStamped& msg) {
  // RViz's "2D Pose Estimate" gives x, y and yaw on the ground plane (z 0, level): a 3D chain
  // keeps z, roll and pitch of its last pose (none before the first scan: 0) with their
  // variances (none before the first scan: unknown).
  geometry_msgs::PoseWithCovarianceStamped pose = msg;
  const auto& o = msg.pose.pose.orientation;
  const Eigen::Quaterniond q(o.w, o.x, o.y, o.z);
  if (q.coeffs().allFinite() && q.norm() > 0.5) {
    // Yaw of a rotation: the heading of its x axis on the ground plane (z-y-x Euler order).
    auto yaw = [](const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); };
    const Eigen::Isometry3d last = last_pose_.value_or(Eigen::Isometry3d::Identity());
    const Eigen::Quaterniond merged(
        Eigen::AngleAxisd(yaw(q.normalized().toRotationMatrix()) - yaw(last.linear()),
                          Eigen::Vector3d::UnitZ()) *
        Eigen::Quaterniond(last.linear()));
    pose.pose.pose.orientation.w = merged.w(), pose.pose.pose.orientation.x = merged.x();
    pose.pose.pose.orientation.y = merged.y(), pose.pose.pose.orientation.z = merged.z();
    pose.pose.pose.position.z = last.translation().z();
    for (const int i : {2, 3, 4}) {  // z, roll, pitch: not given
      for (int j = 0; j < 6; ++j) pose.pose.covariance[std::size_t(6 * i + j)] = 0.0;
      for (int j = 0; j < 6; ++j) pose.pose.covariance[std::size_t(6 * j + i)] = 0.0;
      if (last_covariance_) pose.pose.covariance[std::size_t(7 * i)] = (*last_covariance_)(i, i);
    }
  }
  ChainStart start;
  const std::string refused = parseStart(pose, "initialpose", true, start);
  if (refused.empty()) {
    restartChain(start, "initialpose");
  } else {
    NODELET_WARN("initialpose refused: %s", refused.c_str());
  }
}

std::string ScanMatcherNodelet::parseStart(const geometry_msgs::PoseWithCovarianceStamped& req,
                                           const std::string& source, bool stamp_is_approximate,
                                           ChainStart& start) {
  const auto& p = req.pose.pose;
  const Eigen::Quaterniond q(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
  const Eigen::Vector3d t(p.position.x, p.position.y, p.position.z);
  if (!req.header.frame_id.empty() && req.header.frame_id != params_.map_frame) {
    return "pose must be in map_frame '" + params_.map_frame + "', not '" + req.header.frame_id +
           "'";
  }
  if (!t.allFinite() || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3) {
    return "pose must be finite with a unit quaternion";
  }
  start.pose = Eigen::Isometry3d::Identity();
  start.pose.linear() = q.normalized().toRotationMatrix();
  start.pose.translation() = t;
  // The pose holds at the request's stamp: the next scan's start is moved on by the odometry
  // from that stamp to its own (a zero stamp: the pose holds at the next scan).
  start.odom.reset();
  if (!req.header.stamp.isZero() && params_.hasOdometry()) {
    std::string error;
    start.odom = lookup(params_.odom_frame, params_.base_frame, req.header.stamp, error);
    if (!start.odom && !stamp_is_approximate) {
      return "no odometry at the pose's stamp " + std::to_string(req.header.stamp.toSec()) +
             " s (" + error + "); send it with a zero stamp to start the next scan there";
    }
    if (!start.odom) {
      NODELET_INFO("%s: no odometry at its stamp %.3f s (%s): the pose holds at the next scan",
                   source.c_str(), req.header.stamp.toSec(), error.c_str());
    }
  }
  // The request's covariance; a variance it leaves at 0 (unknown) becomes the one of a scan
  // whose registration was rejected (rejected_sigma_m, rejected_sigma_deg): loose, not the
  // floors of a registration.
  const auto& c = req.pose.covariance;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) start.covariance(i, j) = c[std::size_t(6 * i + j)];
  }
  start.covariance = 0.5 * (start.covariance + start.covariance.transpose());
  const ChainCovarianceSettings& cs = params_.chain;
  const Matrix6d unknown = diagonalCovariance(cs.rejected_sigma_m, cs.rejected_sigma_rad);
  for (int i = 0; i < 6; ++i) {
    if (!(start.covariance(i, i) > 0.0)) start.covariance(i, i) = unknown(i, i);
  }
  return "";
}

void ScanMatcherNodelet::restartChain(const ChainStart& start, const std::string& source) {
  resetState("pose set through " + source);
  matcher_->restartAt(start.pose);
  pending_start_ = PendingStart{start.pose, start.odom};
  chain_->restart(start.covariance);
  anchor_->reset(start.covariance);
}

void ScanMatcherNodelet::resetState(const std::string& why) {
  NODELET_WARN("%s: the next scan starts a new pose chain", why.c_str());
  if (matcher_) matcher_->reset();
  path_.poses.clear();
  last_stamp_.reset();
  dropped_ = rejected_ = tf_failures_ = processed_ = bad_input_ = consecutive_rejections_ = 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    latencies_.clear();
  }
  if (chain_) chain_->restart(std::nullopt);
  if (anchor_) anchor_->reset(std::nullopt);
  pending_start_.reset();
  last_odom_.reset();
  last_twist_.reset();
  last_pose_.reset();
  last_covariance_.reset();
}

std::optional<Eigen::Isometry3d> ScanMatcherNodelet::lookup(const std::string& target,
                                                            const std::string& source,
                                                            const ros::Time& stamp,
                                                            std::string& error) {
  try {
    // A bounded wait at the exact stamp: never the "latest" transform.
    const geometry_msgs::TransformStamped t =
        tf_buffer_->lookupTransform(target, source, stamp, ros::Duration(params_.tf_timeout));
    return tf2::transformToEigen(t);
  } catch (const tf2::TransformException& e) {
    if (!error.empty()) error += "; ";
    error += e.what();
    return std::nullopt;
  }
}

void ScanMatcherNodelet::cloudCallback(const sensor_msgs::PointCloud2ConstPtr& msg) {
  const double received = ros::WallTime::now().toSec();
  if (!initialised_) return;
  countArrival(*msg);
  bool overwritten;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    overwritten = inbox_ != nullptr;
    inbox_ = msg;
    inbox_received_ = received;
  }
  inbox_cv_.notify_one();
  if (overwritten) {
    ++dropped_;
    NODELET_WARN_THROTTLE(5.0, "a scan was dropped: a newer one arrived while the registration "
                               "before it ran (%u dropped)", dropped_.load());
  }
}

void ScanMatcherNodelet::post(std::function<void()> change) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    changes_.push_back(std::move(change));
  }
  inbox_cv_.notify_one();
}

void ScanMatcherNodelet::workerLoop() {
  for (;;) {
    sensor_msgs::PointCloud2ConstPtr msg;
    double received = 0.0;
    std::deque<std::function<void()>> changes;
    {
      std::unique_lock<std::mutex> lock(inbox_mutex_);
      inbox_cv_.wait(lock, [this] { return stopping_ || inbox_ || !changes_.empty(); });
      if (stopping_) return;
      changes.swap(changes_);
      msg.swap(inbox_);
      received = inbox_received_;
    }
    // Nothing may leave this thread: an exception here would end the manager's process.
    for (auto& change : changes) {
      try {
        change();
      } catch (const std::exception& e) {
        NODELET_ERROR("a change to the matcher's state failed: %s", e.what());
      }
    }
    if (!msg) continue;
    try {
      processCloud(*msg, received);
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "scan %u not processed: %s", msg->header.seq, e.what());
    }
  }
}

// processCloud's steps. Each returns false (after publishing the status) when the scan stops
// there; a scan that stops keeps the reference and the pose chain as they were.
void ScanMatcherNodelet::processCloud(const sensor_msgs::PointCloud2& msg, double received) {
  Status status;
  status.header.stamp = msg.header.stamp;
  status.header.frame_id = params_.map_frame;
  status.points_in = msg.width * msg.height;
  Scan scan(msg, received, status);

  if (!checkHeader(scan)) return;
  if (!trackStamps(scan)) return;
  if (!lookupFrames(scan)) return;
  if (!convertPoints(scan)) return;
  const OnlineStep step = registerScan(scan);
  publishPose(scan, step);
  publishStatus(scan, step.reason, step.message);
}

void ScanMatcherNodelet::rejectInput(Scan& scan, const std::string& why) {
  ++bad_input_;
  NODELET_ERROR_THROTTLE(5.0, "cloud %u not used: %s", scan.msg.header.seq, why.c_str());
  publishStatus(scan, GateReason::BadInput, why);
}

void ScanMatcherNodelet::publishStatus(Scan& scan, GateReason reason,
                                       const std::string& message) {
  Status& status = scan.status;
  status.reason = std::uint8_t(reason);
  status.reason_text = toString(reason);
  status.accepted = reason == GateReason::Accepted;
  status.message = message;
  status.rejected_scans = rejected_;
  status.tf_failures = tf_failures_;
  status.dropped_scans = dropped_;
  status.consecutive_rejections = consecutive_rejections_;
  status.latency = ros::WallTime::now().toSec() - scan.received;
  status.data_age = (ros::Time::now() - scan.msg.header.stamp).toSec();
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    latencies_.push_back(status.latency);
    if (latencies_.size() > 200) latencies_.pop_front();
  }
  status_pub_.publish(status);
}

bool ScanMatcherNodelet::checkHeader(Scan& scan) {
  if (scan.msg.header.stamp.isZero()) {
    rejectInput(scan, "cloud has a zero stamp; tf cannot be looked up at it");
    return false;
  }
  if (scan.msg.header.frame_id.empty()) {
    rejectInput(scan, "cloud has an empty frame_id");
    return false;
  }
  return true;
}

bool ScanMatcherNodelet::trackStamps(Scan& scan) {
  const ros::Time stamp = scan.msg.header.stamp;
  if (last_stamp_ && stamp < *last_stamp_) {
    const double back = (*last_stamp_ - stamp).toSec();
    std::ostringstream os;
    os << std::fixed << std::setprecision(3);
    if (back <= params_.time_jump_reset) {
      // Out of order by a little (a driver's or a bag's reordering): not a new chain.
      ++dropped_;
      os << "stamp " << stamp.toSec() << " s is " << back << " s before the last scan's "
         << last_stamp_->toSec() << " s (out of order, within time_jump_reset "
         << params_.time_jump_reset << " s): dropped";
      NODELET_WARN_THROTTLE(5.0, "%s", os.str().c_str());
      publishStatus(scan, GateReason::BadInput, os.str());
      return false;
    }
    // Time went back: a looping bag or a reset clock. One warning, then a fresh start.
    os << "time went backwards from " << last_stamp_->toSec() << " s to " << stamp.toSec()
       << " s (bag loop or clock reset)";
    resetState(os.str());
    scan.status.time_reset = true;
  }
  last_stamp_ = stamp;
  return true;
}

void ScanMatcherNodelet::countArrival(const sensor_msgs::PointCloud2& msg) {
  // Scans the subscriber queue dropped never reach this callback: they are counted from the
  // header.seq gap, as drops and as arrivals of the input rate. roscpp numbers seq when it
  // serialises (the sweep assembler publishes by value, so always); a publisher in the same
  // manager that hands over a pointer keeps its own seq, and its queue drops are not seen.
  const std::uint32_t seq = msg.header.seq;
  std::uint32_t gap = 0;
  if (last_seq_ && seq > *last_seq_ + 1) gap = std::min<std::uint32_t>(seq - *last_seq_ - 1, 10000);
  last_seq_ = seq;
  dropped_ += gap;
  for (std::uint32_t i = 0; i <= gap; ++i) rate_status_->tick();
}

bool ScanMatcherNodelet::lookupFrames(Scan& scan) {
  // The cloud in base_frame at its stamp, and the odometry pose there.
  const ros::Time stamp = scan.msg.header.stamp;
  const std::string& frame = scan.msg.header.frame_id;
  std::string tf_error;
  std::optional<Eigen::Isometry3d> T_base_cloud =
      frame == params_.base_frame ? std::optional<Eigen::Isometry3d>(Eigen::Isometry3d::Identity())
                                  : lookup(params_.base_frame, frame, stamp, tf_error);
  const bool odometry = params_.hasOdometry();
  if (odometry) scan.odom = lookup(params_.odom_frame, params_.base_frame, stamp, tf_error);
  if (scan.status.time_reset && (!T_base_cloud || (odometry && !scan.odom))) {
    // After a jump back by more than the tf cache, the buffer refuses the new (older) tf as
    // TF_OLD_DATA: clear it, so that tf from here on is taken, and look once more.
    NODELET_WARN("tf buffer cleared after the time jump: %s", tf_error.c_str());
    tf_buffer_->clear();
    tf_error.clear();
    if (!T_base_cloud) T_base_cloud = lookup(params_.base_frame, frame, stamp, tf_error);
    if (odometry && !scan.odom) {
      scan.odom = lookup(params_.odom_frame, params_.base_frame, stamp, tf_error);
    }
  }
  scan.status.tf_failed = !T_base_cloud || (odometry && !scan.odom);
  if (scan.status.tf_failed) {
    ++tf_failures_;
    NODELET_WARN_THROTTLE(5.0, "tf missing for scan at %.3f s within %.2f s: %s", stamp.toSec(),
                          params_.tf_timeout, tf_error.c_str());
  }
  if (!T_base_cloud || (!scan.odom && params_.skip_without_tf)) {
    publishStatus(scan, GateReason::SkippedNoTf,
                  (T_base_cloud ? "odometry tf missing, missing_tf_policy = skip: "
                                : "cloud frame cannot be brought into base_frame: ") +
                      tf_error);
    return false;
  }
  scan.T_base_cloud = *T_base_cloud;
  return true;
}

bool ScanMatcherNodelet::convertPoints(Scan& scan) {
  FilterStats fs;
  try {
    const PointArray all = fromCloud(scan.msg, scan.T_base_cloud);
    const std::vector<float> tau =
        params_.time_field.empty() ? std::vector<float>{} : readFloatField(scan.msg, params_.time_field);
    // An unreadable intensity drops the intensity, never the scan.
    std::string intensity_problem;
    const std::vector<float> intensity =
        readIntensity(scan.msg, intensity_problem).value_or(std::vector<float>{});
    if (!intensity_problem.empty()) {
      NODELET_WARN_THROTTLE(10.0, "intensity not carried to ~registered_cloud: %s",
                            intensity_problem.c_str());
    }
    // The points kept, and with them their times and intensities.
    const std::vector<std::uint32_t> kept = keptIndices(all, tau, params_.filter, &fs);
    auto gather = [&kept](const std::vector<float>& v, std::vector<float>& out) {
      out.resize(kept.size());
      for (std::size_t i = 0; i < kept.size(); ++i) out[i] = v[kept[i]];
    };
    gather(all.x, scan.points.x);
    gather(all.y, scan.points.y);
    gather(all.z, scan.points.z);
    if (!intensity.empty()) gather(intensity, scan.intensity.emplace());
    if (!tau.empty()) {
      // A sweep taken over time: a cloud in the odometry frame was placed by tf (the
      // odometry) line by line; one in another frame is taken as rigid (core/deskew.h).
      PointTimes times;
      times.placed_by_odometry = scan.msg.header.frame_id == params_.odom_frame;
      gather(tau, times.tau);
      scan.times = std::move(times);
    }
  } catch (const CloudError& e) {
    rejectInput(scan, e.what());
    return false;
  }
  scan.status.points_valid = std::uint32_t(scan.points.size());
  if (scan.points.empty()) {
    std::ostringstream os;
    os << "cloud has no usable point: " << fs.input << " points, " << fs.non_finite
       << " NaN/inf, " << fs.out_of_range << " outside [range_min, range_max]";
    rejectInput(scan, os.str());
    return false;
  }
  return true;
}

OnlineStep ScanMatcherNodelet::registerScan(Scan& scan) {
  // A chain started by ~set_pose, initialpose or a continuous ~reset: its pose, moved on by the
  // odometry from when it held to this scan.
  if (pending_start_) {
    if (pending_start_->odom && scan.odom) {
      const Eigen::Isometry3d start =
          pending_start_->pose * pending_start_->odom->inverse() * *scan.odom;
      if (start.matrix().allFinite()) {
        matcher_->restartAt(start);
      } else {
        NODELET_WARN("the chain's start moved on by the odometry is not finite: it starts at "
                     "the given pose as it is");
      }
    }
    pending_start_.reset();
  }
  // Register, gate and chain (core).
  const OnlineStep step =
      matcher_->process(scan.points, scan.msg.header.stamp.toSec(), scan.odom,
                        scan.times ? &*scan.times : nullptr);
  ++processed_;
  const RegistrationResult& r = step.result;
  Status& status = scan.status;
  status.J = r.J;
  status.reference_bytes = matcher_->referenceBytes();
  status.workspace_bytes = matcher_->workspaceBytes();
  status.keyframe_bytes = matcher_->keyframeBytes();
  status.J_guess = r.J_guess;
  status.reference_cubes = std::int32_t(r.reference_cubes);
  status.overlap = r.overlap();
  status.points_used = std::uint32_t(r.points_used);
  status.starts_agreeing = r.starts_agreeing;
  status.J_runner_up = r.J_runner_up;
  status.polished = r.polished;
  status.plane_rms = r.plane_rms;
  status.degenerate = r.degenerate;
  status.weak_ratio = r.weak_ratio;
  status.translation_weak_ratio = r.translation_weak_ratio;
  for (int k = 0; k < 6; ++k) {
    status.sigma[std::size_t(k)] = std::sqrt(std::max(0.0, r.covariance(k, k)));
    status.weak_direction[std::size_t(k)] = r.weak_direction(k);
  }
  status.evaluations = r.evaluations;
  status.iterations = r.iterations;
  status.restarts = r.restarts;
  status.registration_time = r.time_s;
  for (int k = 0; k < 6; ++k) {
    status.guess[std::size_t(k)] = step.guess[k];
    status.correction[std::size_t(k)] = step.correction[k];
  }
  status.gate_scale = step.gate_scale;
  status.odometry_guess = step.odometry_guess;
  status.reference_updated = step.reference_updated;
  status.keyframes = std::uint32_t(step.keyframes);
  status.time_reset = status.time_reset || step.time_reset;
  const bool rejected = step.reason != GateReason::Accepted && step.reason != GateReason::FirstScan;
  if (rejected) ++rejected_;
  consecutive_rejections_ = std::uint32_t(step.consecutive_rejections);
  if (step.rejection_alarm) {
    NODELET_ERROR_THROTTLE(5.0, "%d scans in a row rejected (last: %s): poses follow odometry only",
                           step.consecutive_rejections, step.message.c_str());
  } else if (rejected) {
    NODELET_WARN_THROTTLE(2.0, "scan at %.3f s rejected: %s", scan.msg.header.stamp.toSec(),
                          step.message.c_str());
  }
  return step;
}

void ScanMatcherNodelet::publishPose(const Scan& scan, const OnlineStep& step) {
  // Covariance along the chain of keyframes (chain_covariance.h); with the anchored role the
  // published pose is the chain tied to the odometry (odometry_anchor.h), with its covariance.
  const StepCovariance cov = chain_->add(step);
  Eigen::Isometry3d published = step.pose;
  Matrix6d published_cov = cov.pose;
  if (params_.role == NodeParams::Role::Anchored) {
    published = anchor_->add(step.pose, cov.motion, scan.odom);
    published_cov = anchor_->covariance();
  }
  std_msgs::Header header;
  header.stamp = scan.msg.header.stamp;
  header.frame_id = params_.map_frame;

  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header = header;
  pose.pose.pose = toPoseMsg(published);
  pose.pose.covariance = toMsg(published_cov);
  pose_pub_.publish(pose);
  last_pose_ = published;
  last_covariance_ = published_cov;
  last_odom_ = scan.odom;

  nav_msgs::Odometry odometry;
  odometry.header = header;
  odometry.child_frame_id = params_.base_frame;
  odometry.pose = pose.pose;
  odometry.twist.twist = toTwistMsg(Vector6d::Zero());
  odometry.twist.covariance = toMsg(Matrix6d(kUnknownTwistVariance * Matrix6d::Identity()));
  if (step.reason == GateReason::FirstScan) last_twist_.reset();
  if (step.accepted && step.interval > 0.0) {
    // Mean velocity since the last registered scan, in base_frame at this scan: v = R^T t / dt,
    // w = theta / dt (the rotation vector is the same in both frames: it lies on the axis).
    const Eigen::AngleAxisd aa(step.motion.linear());
    Vector6d twist;
    twist << step.motion.linear().transpose() * step.motion.translation() / step.interval,
        aa.axis() * aa.angle() / step.interval;
    odometry.twist.twist = toTwistMsg(twist);
    odometry.twist.covariance = toMsg(twistCovariance(
        rotateCovariance(cov.increment, step.increment.linear().transpose()),  // base_frame axes
        step.interval, twist - last_twist_.value_or(Vector6d::Zero())));
    last_twist_ = twist;
  }
  odom_pub_.publish(odometry);

  geometry_msgs::PoseStamped path_pose;
  path_pose.header = header;
  path_pose.pose = pose.pose.pose;
  path_.header.stamp = header.stamp;
  path_.poses.push_back(path_pose);
  if (path_.poses.size() > std::size_t(params_.path_max_length)) {
    path_.poses.erase(path_.poses.begin(),
                      path_.poses.end() - std::ptrdiff_t(params_.path_max_length));
  }
  path_pub_.publish(path_);

  if (cloud_pub_.getNumSubscribers() > 0) {
    // The sweep as registered: re-placed with the registered motion when it was de-skewed.
    const PointArray& points = step.deskewed ? step.deskewed_points : scan.points;
    cloud_pub_.publish(
        toCloud(points, published, header, scan.intensity ? &*scan.intensity : nullptr));
  }

  if (tf_broadcaster_ && scan.odom) {
    // REP-105: map -> odom such that map -> odom -> base_link equals the registered pose.
    const Eigen::Isometry3d map_odom = published * scan.odom->inverse();
    {
      std::lock_guard<std::mutex> lock(tf_mutex_);
      const bool first = !map_odom_;
      map_odom_ = map_odom;
      // The first one also at the scan's stamp: valid from there, not only from now + tolerance.
      if (first) sendMapOdomAt(header.stamp);
    }
    sendMapOdom();
  }
}

void ScanMatcherNodelet::sendMapOdom() {
  std::lock_guard<std::mutex> lock(tf_mutex_);
  if (!map_odom_ || !tf_broadcaster_) return;
  // Valid from now until the next update: post-dated so that lookups at the current time (a
  // costmap, a planner) do not need to extrapolate.
  sendMapOdomAt(ros::Time::now() + ros::Duration(params_.transform_tolerance));
}

void ScanMatcherNodelet::sendMapOdomAt(const ros::Time& stamp) {
  // Never the same stamp twice: under simulated time a paused or slow clock would repeat it,
  // and tf listeners warn TF_REPEATED_DATA for each repetition.
  if (last_map_odom_stamp_ && stamp == *last_map_odom_stamp_) return;
  last_map_odom_stamp_ = stamp;
  tf_broadcaster_->sendTransform(
      stampedTransform(*map_odom_, params_.map_frame, params_.odom_frame, stamp));
}

void ScanMatcherNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  using diagnostic_msgs::DiagnosticStatus;
  if (!init_error_.empty()) {
    stat.summary(DiagnosticStatus::ERROR, "not running: " + init_error_);
    return;
  }
  std::vector<double> latencies;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    latencies.assign(latencies_.begin(), latencies_.end());
  }
  const double median = quantile(latencies, 0.5), p95 = quantile(latencies, 0.95);
  const std::uint32_t processed = processed_, rejected = rejected_, tf_failures = tf_failures_;
  const std::uint32_t bad_input = bad_input_, dropped = dropped_;
  const std::uint32_t consecutive = consecutive_rejections_;
  stat.add("scans processed", processed);
  stat.add("scans rejected", rejected);
  stat.add("consecutive rejections", consecutive);
  stat.add("tf failures", tf_failures);
  stat.add("bad input scans", bad_input);
  stat.add("dropped scans", dropped);
  stat.add("latency median [s]", median);
  stat.add("latency p95 [s]", p95);
  if (consecutive >= std::uint32_t(max_consecutive_rejections_.load())) {
    stat.summary(DiagnosticStatus::ERROR, "consecutive rejections: poses follow odometry only");
  } else if (median > params_.max_latency) {
    stat.summary(DiagnosticStatus::WARN, "latency above max_latency");
  } else if (rejected > 0 || tf_failures > 0 || dropped > 0 || bad_input > 0) {
    stat.summary(DiagnosticStatus::WARN, "some scans rejected, dropped or without tf");
  } else {
    stat.summary(DiagnosticStatus::OK, processed ? "registering" : "waiting for scans");
  }
  if (!param_warnings_.empty()) {
    stat.add("unknown parameters", param_warnings_);
    stat.mergeSummary(DiagnosticStatus::WARN, "unknown parameters (misspelt?)");
  }
}

}  // namespace cube_scan_matcher

PLUGINLIB_EXPORT_CLASS(cube_scan_matcher::ScanMatcherNodelet, nodelet::Nodelet)
