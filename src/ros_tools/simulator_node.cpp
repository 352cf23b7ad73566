// simulator_node: the paper's tilting 2D scanner (section 3.1) on a robot in a procedural scene,
// with a simulated DGPS/IMU odometry (configurable errors) and the exact truth on ground_truth
// (PoseStamped, frame map = the world, which equals odom at the first sweep). Two outputs
// (~input, docs/method.md "The simulator"):
//  - sweeps: a sweep taken from one pose at a time (stop and go) and assembled in the simulator:
//    per sweep tf odom -> base_link, the cloud in the scanner frame at the same stamp and the
//    truth; the static base_link -> scanner mount is published once.
//  - lines: what a real driver publishes while the robot drives: one sensor_msgs/LaserScan per
//    2D line at line_rate, the tilt going up and down without pause, with tf odom -> base_link
//    and mount -> scanner (the tilt) at each line's stamp; the sweep assembler turns them into
//    clouds. The robot stands still for the first sweep, then drives (sim::DrivenPath).
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <random>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/read_param.h"
#include "cube_scan_matcher/ros/transforms.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

namespace {

/// An organised cloud (height = 2D scans, width = beams per scan) with NaN for no return.
sensor_msgs::PointCloud2 organised(const PointArray& pts, int width, int height,
                                   const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 c = toCloud(pts, Eigen::Isometry3d::Identity(), header);
  c.width = std::uint32_t(width);
  c.height = std::uint32_t(height);
  c.row_step = c.point_step * c.width;
  c.is_dense = false;
  return c;
}

/// What both outputs share.
struct Common {
  std::string scene_name, odom_mode, odom_frame, base_frame, scanner_frame, map_frame;
  int seed = 1, sweeps = 0;
  sim::ScannerModel model;
  double wait_for_subscriber = 30.0, start_delay = 1.0;
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();  ///< eq. 1's sensor frame in base_link
};

void publishTruth(ros::Publisher& pub, const Eigen::Isometry3d& truth, const std::string& frame,
                  const ros::Time& stamp) {
  geometry_msgs::PoseStamped gt;
  gt.header.stamp = stamp;
  gt.header.frame_id = frame;
  gt.pose = tf2::toMsg(truth);
  pub.publish(gt);
}

/// Waits for a subscriber of `pub` (at most wait_for_subscriber), then start_delay, so that tf
/// listeners and the other subscribers have connected.
void waitForSubscriber(const ros::Publisher& pub, const Common& c) {
  const ros::WallTime wait_end = ros::WallTime::now() + ros::WallDuration(c.wait_for_subscriber);
  while (ros::ok() && pub.getNumSubscribers() == 0 && ros::WallTime::now() < wait_end) {
    ros::WallDuration(0.05).sleep();
  }
  ros::WallDuration(c.start_delay).sleep();
}

// ---- input: sweeps (stop and go, assembled in the simulator) ------------------------------

void runSweeps(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Common& c) {
  const double period = readParam(pnh, "period", 1.0, 0.05, 3600.0);
  const bool organized = pnh.param("organized", false);
  // Odometry (odom -> base_link) for the first N sweeps only, then none: a lost odometry.
  const int odometry_sweeps = readParam(pnh, "odometry_sweeps", 0, 0, 1 << 30);  // 0 = all
  sim::MotionSettings motion;
  motion.step_min = readParam(pnh, "step_min", motion.step_min, 0.0, 20.0);
  motion.step_max = readParam(pnh, "step_max", motion.step_max, motion.step_min, 20.0);
  motion.yaw_change_max_deg = readParam(pnh, "yaw_change_max_deg", motion.yaw_change_max_deg, 0.0, 90.0, "deg");
  const sim::ScannerModel& model = c.model;

  const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(c.scene_name), std::uint64_t(c.seed));
  sim::RobotMotion robot(scene, motion, std::uint64_t(c.seed) + 1);
  sim::OdometrySimulator odometry(sim::odometryErrorFromString(c.odom_mode), std::uint64_t(c.seed) + 2);
  std::mt19937_64 rng(std::uint64_t(c.seed) + 3);

  ros::Publisher cloud_pub = nh.advertise<sensor_msgs::PointCloud2>("assembled_cloud", 2);
  ros::Publisher truth_pub = nh.advertise<geometry_msgs::PoseStamped>("ground_truth", 10);
  tf2_ros::TransformBroadcaster tf_pub;
  tf2_ros::StaticTransformBroadcaster static_pub;
  static_pub.sendTransform(stampedTransform(c.mount, c.base_frame, c.scanner_frame, ros::Time(0)));
  ROS_INFO("simulator: %s scene (seed %d), %d x %d beams, odometry errors '%s', a sweep every %.2f s",
           c.scene_name.c_str(), c.seed, model.phiCount(), model.psiCount(), c.odom_mode.c_str(), period);

  // Odometry as a robot's: odom -> base_link at 50 Hz, stamped now, holding the last sweep's
  // pose between sweeps (the robot moves in steps), so that tf is there at the current time.
  std::mutex odom_mutex;
  std::optional<Eigen::Isometry3d> last_odom;
  ros::Timer odom_timer = nh.createTimer(ros::Duration(0.02), [&](const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(odom_mutex);
    if (last_odom) tf_pub.sendTransform(stampedTransform(*last_odom, c.odom_frame, c.base_frame, ros::Time::now()));
  });
  ros::AsyncSpinner spinner(1);
  spinner.start();

  waitForSubscriber(cloud_pub, c);
  ros::Rate rate(1.0 / period);
  for (int k = 0; ros::ok() && (c.sweeps == 0 || k < c.sweeps); ++k) {
    if (k > 0) robot.advance();
    const Eigen::Isometry3d truth = robot.pose();
    const Eigen::Isometry3d odom = odometry.next(truth);
    sim::SweepOptions options;
    options.keep_invalid = organized;
    const double t = k * period;  // what moves (the crowd's people and cars) is where it is now
    const PointArray pts =
        sim::scan(scene.movers.empty() ? scene : scene.at(t), model, truth * c.mount, rng, options);
    ros::Time stamp;
    {
      std::lock_guard<std::mutex> lock(odom_mutex);
      stamp = ros::Time::now();
      if (odometry_sweeps == 0 || k < odometry_sweeps) {
        last_odom = odom;
        tf_pub.sendTransform(stampedTransform(odom, c.odom_frame, c.base_frame, stamp));
      } else {
        if (k == odometry_sweeps) ROS_WARN("simulator: odometry tf stops at sweep %d (~odometry_sweeps)", k);
        last_odom.reset();
      }
    }
    publishTruth(truth_pub, truth, c.map_frame, stamp);
    ros::WallDuration(0.02).sleep();  // tf first, then the cloud that needs it
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = c.scanner_frame;
    cloud_pub.publish(organized ? organised(pts, model.phiCount(), model.psiCount(), header)
                                : toCloud(pts, Eigen::Isometry3d::Identity(), header));
    rate.sleep();
  }
  ROS_INFO("simulator: %d sweeps published", c.sweeps);
  ros::waitForShutdown();  // keep tf and topics alive until stopped
}

// ---- input: lines (a driver's LaserScan lines while driving) ------------------------------

/// The robot's path in lines mode, t [s] since it started driving: sim::DrivenPath legs along
/// the world's x axis (the scenes keep a track along it), forward from (0, y0) until the first
/// knot (a multiple of the zigzag interval, i.e. a sweep's end) beyond x_max, then backward (at
/// -speed, still facing +x) until the first knot beyond x_min, and so on. The pose is
/// continuous; the velocity changes only at knots, where the odometry's constant-velocity
/// pieces change anyway. A new leg keeps the zigzag's axis and its alternation.
class ShuttlePath {
 public:
  ShuttlePath(const sim::Scene& scene, const sim::DrivenPathSettings& settings, double y0, double x_min,
              double x_max)
      : scene_(scene), s_(settings), x_min_(x_min), x_max_(x_max) {
    legs_.push_back({0.0, 1, 1, sim::DrivenPath(scene_, s_, 0.0, y0, 0.0)});
  }

  /// T_world_base at t >= 0 (t < 0: the start pose). Legs are added as t reaches them.
  Eigen::Isometry3d at(double t) {
    t = std::max(t, 0.0);
    while (checked_knots_ * s_.interval <= t) {
      const double tk = checked_knots_ * s_.interval;
      ++checked_knots_;
      const Leg& leg = legs_.back();
      const Eigen::Isometry3d pose = leg.path.at(tk - leg.t0);
      const double x = pose.translation().x();
      if ((leg.direction > 0 && x > x_max_) || (leg.direction < 0 && x < x_min_)) {
        // The heading at the knot is -yaw_sign * w * interval / 2 after an even number of
        // intervals of the leg, the opposite after an odd one: the new leg starts there.
        const long m = std::lround((tk - leg.t0) / s_.interval);
        const int yaw_sign = m % 2 == 0 ? leg.yaw_sign : -leg.yaw_sign;
        sim::DrivenPathSettings s = s_;
        s.speed = -leg.direction * s_.speed;
        s.yaw_rate_deg = yaw_sign * s_.yaw_rate_deg;
        legs_.push_back({tk, -leg.direction, yaw_sign,
                         sim::DrivenPath(scene_, s, pose.translation().x(), pose.translation().y(), 0.0)});
      }
    }
    auto leg = std::find_if(legs_.rbegin(), legs_.rend(), [&](const Leg& l) { return l.t0 <= t; });
    return leg->path.at(t - leg->t0);
  }

 private:
  struct Leg {
    double t0;      ///< [s] start of the leg
    int direction;  ///< +1 forward (+x), -1 backward
    int yaw_sign;   ///< sign of the yaw rate in the leg's first interval
    sim::DrivenPath path;
  };
  const sim::Scene& scene_;
  sim::DrivenPathSettings s_;
  double x_min_, x_max_;
  std::vector<Leg> legs_;
  long checked_knots_ = 1;  // knot 0 is the start
};

/// The first lateral offset y0 (0, then +-0.5 m ... +-2 m) whose path keeps base_link 0.3 m
/// clear of every solid over `horizon` [s] of driving, checked every 0.25 m of travel (and
/// every 0.25 s); throws if there is none.
double chooseLane(const sim::Scene& scene, const sim::DrivenPathSettings& settings, double x_min,
                  double x_max, double horizon) {
  const double step = std::min(0.25, settings.speed > 0.0 ? 0.25 / settings.speed : 0.25);
  for (double y0 : {0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 2.0, -2.0}) {
    ShuttlePath path(scene, settings, y0, x_min, x_max);
    bool free = true;
    for (double t = 0.0; t <= horizon && free; t += step) {
      free = !scene.insideSolid(path.at(t).translation(), 0.3);
    }
    if (free) return y0;
  }
  throw std::runtime_error("no free track along the x axis within |y| <= 2 m for the robot in this scene");
}

void runLines(ros::NodeHandle& nh, ros::NodeHandle& pnh, const Common& c) {
  const sim::ScannerModel& model = c.model;
  const std::string mount_frame = pnh.param<std::string>("mount_frame", "laser_mount");
  // 75 Hz: a SICK LMS-class 2D scanner's line rate; with the paper's 181 lines (psi_step 1/3
  // deg over 60 deg) a sweep takes 181 / 75 = 2.41 s.
  const double line_rate = readParam(pnh, "line_rate", 75.0, 1.0, 1000.0, "Hz");
  sim::DrivenPathSettings drive;
  drive.speed = readParam(pnh, "speed", 1.0, 0.0, 5.0, "m/s");
  drive.yaw_rate_deg = readParam(pnh, "yaw_rate_deg", 10.0, 0.0, 90.0, "deg/s");
  if (mount_frame.empty() || mount_frame == c.scanner_frame || mount_frame == c.base_frame) {
    throw ParamError("parameter ~mount_frame = '" + mount_frame +
                     "' must be a frame name distinct from ~scanner_frame and ~base_frame");
  }
  const int lines = model.psiCount();  // per sweep, psi_min .. psi_max (or back)
  if (lines < 2) {
    throw ParamError("parameters ~psi_min_deg, ~psi_max_deg, ~psi_step_deg give " + std::to_string(lines) +
                     " lines per sweep; a tilting sweep needs psi_max > psi_min (at least 2 lines)");
  }
  // Sweep k has lines n = k L .. k L + L - 1 (L = lines), line n at n / line_rate after the
  // start; the tilt turns after a sweep's last line, which the next sweep's first line repeats
  // (one line's dwell at each turning point, as sim::scanDuringMotion's sweeps back to back).
  // A sweep's stamp (its last line's) is its knot; knots are T = L / line_rate apart, the
  // sweep duration and the zigzag's interval.
  const double sweep_duration = lines / line_rate;
  drive.interval = sweep_duration;
  auto lineTime = [&](long n) { return double(n) / line_rate; };  // [s] after the start
  auto knotTime = [&](long k) { return lineTime(k * lines + lines - 1); };

  const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(c.scene_name), std::uint64_t(c.seed));
  const sim::MotionSettings shuttle;  // x_min, x_max: where the robot turns back
  // The lane is checked over the run (and one full shuttle there and back while driving on).
  const double shuttle_time =
      drive.speed > 0.0 ? 2.0 * (shuttle.x_max - shuttle.x_min) / drive.speed + 4.0 * sweep_duration : 0.0;
  const double horizon = c.sweeps > 0 ? std::min(shuttle_time, c.sweeps * sweep_duration) : shuttle_time;
  const double y0 = chooseLane(scene, drive, shuttle.x_min, shuttle.x_max, horizon);
  ShuttlePath path(scene, drive, y0, shuttle.x_min, shuttle.x_max);
  // Standing still until the first sweep's end (its knot), then driving.
  auto truthAt = [&](double s) { return path.at(s - knotTime(0)); };
  sim::OdometrySimulator odometry(sim::odometryErrorFromString(c.odom_mode), std::uint64_t(c.seed) + 2);
  std::mt19937_64 rng(std::uint64_t(c.seed) + 3);

  ros::Publisher scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan", 200);
  ros::Publisher truth_pub = nh.advertise<geometry_msgs::PoseStamped>("ground_truth", 10);
  tf2_ros::TransformBroadcaster tf_pub;
  tf2_ros::StaticTransformBroadcaster static_pub;
  static_pub.sendTransform(stampedTransform(c.mount, c.base_frame, mount_frame, ros::Time(0)));
  ROS_INFO("simulator: %s scene (seed %d), LaserScan lines of %d beams at %.1f Hz, %d lines per sweep "
           "(%.3f s), odometry errors '%s', driving at %.2f m/s, yaw rate +-%.1f deg/s (track y = %.1f m) "
           "after a first sweep standing still",
           c.scene_name.c_str(), c.seed, model.phiCount(), line_rate, lines, sweep_duration,
           c.odom_mode.c_str(), drive.speed, drive.yaw_rate_deg, y0);

  // The LaserScan's constant part: eq. 1's phi; the beams of a line are treated as
  // simultaneous (time_increment 0), as the core simulator casts them.
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = c.scanner_frame;
  scan.angle_min = float(deg2rad(model.phi_min_deg));
  scan.angle_increment = float(deg2rad(model.phi_step_deg));
  scan.angle_max = float(deg2rad(model.phi_min_deg + (model.phiCount() - 1) * model.phi_step_deg));
  scan.time_increment = 0.0f;
  scan.scan_time = float(1.0 / line_rate);
  scan.range_min = 0.05f;
  scan.range_max = float(model.max_range);

  auto tilt = [&](double psi) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitX()).toRotationMatrix();
    return T;
  };

  waitForSubscriber(scan_pub, c);
  const ros::Time start = ros::Time::now();
  Eigen::Isometry3d odom_prev = Eigen::Isometry3d::Identity(), odom_next = Eigen::Isometry3d::Identity();
  Twist xi = Twist::Zero();
  double psi = 0.0;
  long behind_lines = 0;
  // After the last sweep the tilt goes on for half a sweep with the robot standing: the
  // assembler needs the turn after a sweep's last line to close it.
  const long trailing = lines / 2;
  const long total = c.sweeps > 0 ? long(c.sweeps) * lines + trailing : std::numeric_limits<long>::max();
  for (long n = 0; ros::ok() && n < total; ++n) {
    const long k = n / lines, j = n % lines;
    const bool after_run = c.sweeps > 0 && k >= c.sweeps;
    if (j == 0 && !after_run) {
      // The odometry at this sweep's end (the path's truth is known ahead): the lines between
      // the knots get it at constant velocity, as the matcher's de-skew assumes.
      odom_prev = odom_next;
      odom_next = odometry.next(truthAt(knotTime(k)));  // the first equals the truth
      xi = k == 0 ? Twist::Zero() : logMotion(odom_prev.inverse() * odom_next);
    }
    const double s = after_run ? knotTime(c.sweeps - 1) : lineTime(n);  // the robot's time
    const double tau = s - knotTime(after_run ? c.sweeps - 1 : k);      // [s] <= 0
    const Eigen::Isometry3d truth = truthAt(s);
    const Eigen::Isometry3d odom = k == 0 || after_run ? odom_next : odom_next * motionAt(xi, tau, sweep_duration);
    const long index = k % 2 == 0 ? j : lines - 1 - j;  // up, then down
    psi = deg2rad(model.psi_min_deg + index * model.psi_step_deg);

    const ros::Time stamp = start + ros::Duration(lineTime(n));
    if (ros::Time::now() < stamp) {
      ros::Time::sleepUntil(stamp);
    } else if (ros::Time::now() - stamp > ros::Duration(0.1)) {
      ++behind_lines;
      ROS_WARN_THROTTLE(5.0, "simulator: ray casting is behind the line rate by %.2f s (%ld lines so far); "
                        "the lines keep their due stamps", (ros::Time::now() - stamp).toSec(), behind_lines);
    }
    const sim::Scene moved = scene.movers.empty() ? sim::Scene() : scene.at(lineTime(n));
    const PointArray pts =
        sim::scanLine(scene.movers.empty() ? scene : moved, model, truth * c.mount, psi, rng, true);
    scan.header.stamp = stamp;
    scan.ranges.resize(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3f p = pts.point(i);
      // REP 117: +inf for no return (the simulator's NaN point).
      scan.ranges[i] = std::isfinite(p.x()) ? p.norm() : std::numeric_limits<float>::infinity();
    }
    tf_pub.sendTransform({stampedTransform(odom, c.odom_frame, c.base_frame, stamp),
                          stampedTransform(tilt(psi), mount_frame, c.scanner_frame, stamp)});
    scan_pub.publish(scan);  // after its tf
    if (j == lines - 1 && !after_run) publishTruth(truth_pub, truth, c.map_frame, stamp);
  }
  if (c.sweeps > 0) {
    ROS_INFO("simulator: %d sweeps published (%ld lines%s)", c.sweeps, total,
             behind_lines > 0 ? ", some behind the line rate" : "");
  }
  // The robot stands at its last pose: tf at the current time, so that lookups "now" succeed.
  const Eigen::Isometry3d odom_last = odom_next;
  ros::Timer hold = nh.createTimer(ros::Duration(0.02), [&](const ros::TimerEvent&) {
    const ros::Time now = ros::Time::now();
    tf_pub.sendTransform({stampedTransform(odom_last, c.odom_frame, c.base_frame, now),
                          stampedTransform(tilt(psi), mount_frame, c.scanner_frame, now)});
  });
  ros::spin();
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "simulator");
  ros::NodeHandle nh, pnh("~");
  try {
    Common c;
    const std::string input = pnh.param<std::string>("input", "sweeps");
    if (input != "sweeps" && input != "lines") {
      throw ParamError("parameter ~input = '" + input + "' must be sweeps or lines");
    }
    pnh.param<std::string>("scene", c.scene_name, "urban");
    pnh.param<std::string>("odometry_error", c.odom_mode, "big");
    pnh.param<std::string>("odom_frame", c.odom_frame, "odom");
    pnh.param<std::string>("base_frame", c.base_frame, "base_link");
    pnh.param<std::string>("scanner_frame", c.scanner_frame, "laser");
    pnh.param<std::string>("map_frame", c.map_frame, "map");
    c.seed = readParam(pnh, "seed", 1, 0, 1 << 30);
    c.sweeps = readParam(pnh, "sweeps", 0, 0, 1 << 30);  // 0 = until stopped
    sim::ScannerModel& model = c.model;
    model.phi_step_deg = readParam(pnh, "phi_step_deg", model.phi_step_deg, 0.05, 10.0, "deg");
    model.psi_min_deg = readParam(pnh, "psi_min_deg", model.psi_min_deg, -89.0, 89.0, "deg");
    model.psi_max_deg = readParam(pnh, "psi_max_deg", model.psi_max_deg, -89.0, 89.0, "deg");
    model.psi_step_deg = readParam(pnh, "psi_step_deg", model.psi_step_deg, 0.05, 10.0, "deg");
    model.max_range = readParam(pnh, "range_max", model.max_range, 1.0, 1000.0, "m");
    model.range_noise = readParam(pnh, "range_noise", model.range_noise, 0.0, 1.0);
    c.wait_for_subscriber = readParam(pnh, "wait_for_subscriber", 30.0, 0.0, 3600.0);
    c.start_delay = readParam(pnh, "start_delay", 1.0, 0.0, 3600.0);
    c.mount.linear() = sim::sensorToBodyRotation();
    c.mount.translation() = Eigen::Vector3d(0.1, 0.0, 0.4);  // scanner 0.4 m above base_link
    // Parameters of the other input are not read: say so rather than ignore them silently.
    const std::vector<std::string> other =
        input == "lines" ? std::vector<std::string>{"period", "organized", "step_min", "step_max", "yaw_change_max_deg",
                                                            "odometry_sweeps"}
                         : std::vector<std::string>{"line_rate", "speed", "yaw_rate_deg", "mount_frame"};
    for (const std::string& name : other) {
      if (pnh.hasParam(name)) ROS_WARN("simulator: ~%s is not used with input %s", name.c_str(), input.c_str());
    }
    if (input == "lines") {
      runLines(nh, pnh, c);
    } else {
      runSweeps(nh, pnh, c);
    }
  } catch (const std::exception& e) {
    ROS_FATAL("simulator: %s", e.what());
    return 1;
  }
  return 0;
}
