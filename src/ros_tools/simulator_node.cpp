// simulator_node: a simulated tilting 2D scanner plus assembler (paper section 3.1) on a robot
// driving through a procedural scene. Per sweep it publishes tf odom -> base_link from a
// simulated DGPS/IMU (with configurable errors), the assembled cloud in the scanner frame at
// the same stamp, and the exact pose on ~ground_truth (frame map = the world, which equals odom
// at the first sweep). The static base_link -> scanner mount is published once.
#include <mutex>
#include <optional>
#include <random>

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/params.h"
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

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "simulator");
  ros::NodeHandle nh, pnh("~");
  try {
    std::string scene_name, odom_mode, odom_frame, base_frame, scanner_frame, map_frame;
    pnh.param<std::string>("scene", scene_name, "urban");
    pnh.param<std::string>("odometry_error", odom_mode, "big");
    pnh.param<std::string>("odom_frame", odom_frame, "odom");
    pnh.param<std::string>("base_frame", base_frame, "base_link");
    pnh.param<std::string>("scanner_frame", scanner_frame, "laser");
    pnh.param<std::string>("map_frame", map_frame, "map");
    const int seed = readParam(pnh, "seed", 1, 0, 1 << 30);
    const int sweeps = readParam(pnh, "sweeps", 0, 0, 1 << 30);  // 0 = until stopped
    const double period = readParam(pnh, "period", 1.0, 0.05, 3600.0);
    const bool organized = pnh.param("organized", false);
    sim::ScannerModel model;
    model.phi_step_deg = readParam(pnh, "phi_step", model.phi_step_deg, 0.05, 10.0);
    model.psi_min_deg = readParam(pnh, "psi_min", model.psi_min_deg, -89.0, 89.0);
    model.psi_max_deg = readParam(pnh, "psi_max", model.psi_max_deg, -89.0, 89.0);
    model.psi_step_deg = readParam(pnh, "psi_step", model.psi_step_deg, 0.05, 10.0);
    model.max_range = readParam(pnh, "max_range", model.max_range, 1.0, 1000.0);
    model.range_noise = readParam(pnh, "range_noise", model.range_noise, 0.0, 1.0);
    sim::MotionSettings motion;
    motion.step_min = readParam(pnh, "step_min", motion.step_min, 0.0, 20.0);
    motion.step_max = readParam(pnh, "step_max", motion.step_max, motion.step_min, 20.0);
    motion.yaw_change_max_deg = readParam(pnh, "yaw_change_max", motion.yaw_change_max_deg, 0.0, 90.0);
    const double wait_for_subscriber = readParam(pnh, "wait_for_subscriber", 30.0, 0.0, 3600.0);
    const double start_delay = readParam(pnh, "start_delay", 1.0, 0.0, 3600.0);

    const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), std::uint64_t(seed));
    sim::RobotMotion robot(scene, motion, std::uint64_t(seed) + 1);
    sim::OdometrySimulator odometry(sim::odometryErrorFromString(odom_mode), std::uint64_t(seed) + 2);
    std::mt19937_64 rng(std::uint64_t(seed) + 3);

    ros::Publisher cloud_pub = nh.advertise<sensor_msgs::PointCloud2>("assembled_cloud", 2);
    ros::Publisher truth_pub = nh.advertise<geometry_msgs::PoseStamped>("ground_truth", 10);
    tf2_ros::TransformBroadcaster tf_pub;
    tf2_ros::StaticTransformBroadcaster static_pub;
    Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
    mount.linear() = sim::sensorToBodyRotation();
    mount.translation() = Eigen::Vector3d(0.1, 0.0, 0.4);  // scanner 0.4 m above base_link
    static_pub.sendTransform(stampedTransform(mount, base_frame, scanner_frame, ros::Time(0)));
    ROS_INFO("simulator: %s scene (seed %d), %d x %d beams, odometry errors '%s', a sweep every %.2f s",
             scene_name.c_str(), seed, model.phiCount(), model.psiCount(), odom_mode.c_str(), period);

    // Odometry as a robot's: odom -> base_link at 50 Hz, stamped now, holding the last sweep's
    // pose between sweeps (the robot moves in steps), so that tf is there at the current time.
    std::mutex odom_mutex;
    std::optional<Eigen::Isometry3d> last_odom;
    ros::Timer odom_timer = nh.createTimer(ros::Duration(0.02), [&](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(odom_mutex);
      if (last_odom) tf_pub.sendTransform(stampedTransform(*last_odom, odom_frame, base_frame, ros::Time::now()));
    });
    ros::AsyncSpinner spinner(1);
    spinner.start();

    const ros::WallTime wait_end = ros::WallTime::now() + ros::WallDuration(wait_for_subscriber);
    while (ros::ok() && cloud_pub.getNumSubscribers() == 0 && ros::WallTime::now() < wait_end) {
      ros::WallDuration(0.05).sleep();
    }
    ros::WallDuration(start_delay).sleep();  // let tf listeners and other subscribers connect
    ros::Rate rate(1.0 / period);
    for (int k = 0; ros::ok() && (sweeps == 0 || k < sweeps); ++k) {
      if (k > 0) robot.advance();
      const Eigen::Isometry3d truth = robot.pose();
      const Eigen::Isometry3d odom = odometry.next(truth);
      sim::SweepOptions options;
      options.keep_invalid = organized;
      const double t = k * period;  // what moves (the crowd's people and cars) is where it is now
      const PointArray pts =
          sim::scan(scene.movers.empty() ? scene : scene.at(t), model, truth * mount, rng, options);
      ros::Time stamp;
      {
        std::lock_guard<std::mutex> lock(odom_mutex);
        stamp = ros::Time::now();
        last_odom = odom;
        tf_pub.sendTransform(stampedTransform(odom, odom_frame, base_frame, stamp));
      }
      geometry_msgs::PoseStamped gt;
      gt.header.stamp = stamp;
      gt.header.frame_id = map_frame;
      gt.pose = tf2::toMsg(truth);
      truth_pub.publish(gt);
      ros::WallDuration(0.02).sleep();  // tf first, then the cloud that needs it
      std_msgs::Header header;
      header.stamp = stamp;
      header.frame_id = scanner_frame;
      cloud_pub.publish(organized ? organised(pts, model.phiCount(), model.psiCount(), header)
                                  : toCloud(pts, Eigen::Isometry3d::Identity(), header));
      rate.sleep();
    }
    ROS_INFO("simulator: %d sweeps published", sweeps);
    ros::waitForShutdown();  // keep tf and topics alive until stopped
  } catch (const std::exception& e) {
    ROS_FATAL("simulator: %s", e.what());
    return 1;
  }
  return 0;
}
