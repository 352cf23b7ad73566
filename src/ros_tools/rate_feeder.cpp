// rate_feeder: the nodelet at robot rates. Simulates `distinct` organised sweeps
// (361 x 181 = 65,341 points each, NaN for no return) along a driven path sampled at the feed
// rate, then publishes them at `rate` [Hz] for `duration` [s] with fresh stamps, driving
// forward along the path and back (so the motion stays continuous and time never goes back,
// unlike a looped bag), each with its odom -> base_link tf at the same stamp. It listens to
// ~status of the matcher and prints, at the end: clouds published and answered, accepted,
// dropped, the data age (stamp -> published pose) and latency quantiles, the registration
// time, and the memory the matcher reports for its reference grids.
//   rosrun cube_scan_matcher rate_feeder _rate:=20 _duration:=60
#include <algorithm>
#include <cstdio>
#include <mutex>
#include <random>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>

#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/read_param.h"
#include "cube_scan_matcher/ros/transforms.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"

using namespace cube_scan_matcher;

int main(int argc, char** argv) {
  ros::init(argc, argv, "rate_feeder");
  ros::NodeHandle nh, pnh("~");
  try {
    const std::string scene_name = pnh.param<std::string>("scene", "urban");
    const std::string status_topic = pnh.param<std::string>("status", "scan_matcher/status");
    const int seed = readParam(pnh, "seed", 1, 0, 1 << 30);
    const double rate = readParam(pnh, "rate", 20.0, 0.1, 1000.0, "Hz");
    const double duration = readParam(pnh, "duration", 60.0, 1.0, 86400.0, "s");
    const int distinct = readParam(pnh, "distinct", 40, 2, 10000);
    const double speed = readParam(pnh, "speed", 1.0, 0.0, 20.0, "m/s");
    const double yaw_rate = readParam(pnh, "yaw_rate_deg", 10.0, -90.0, 90.0, "deg/s");
    const double wait_for_subscriber = readParam(pnh, "wait_for_subscriber", 30.0, 0.0, 3600.0, "s");
    // A smoke check for scripts and CTest (not a timing check): fewer answers is an error.
    const int min_answered = readParam(pnh, "min_answered", 1, 0, 1 << 30);

    // The sweeps: organised clouds in base_link along the path, one per feed period.
    const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), std::uint64_t(seed));
    const sim::DrivenPath path(scene, {speed, yaw_rate, 2.0, 1.0}, 20.0, 0.0, 0.0);
    const sim::ScannerModel model;
    Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
    mount.linear() = sim::sensorToBodyRotation();
    std::mt19937_64 rng(std::uint64_t(seed) + 3);
    std::vector<sensor_msgs::PointCloud2> clouds;
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k < distinct && ros::ok(); ++k) {
      poses.push_back(path.at(k / rate));
      const PointArray sensor = sim::scan(scene, model, poses.back() * mount, rng, sim::SweepOptions{true});
      std_msgs::Header header;
      header.frame_id = "base_link";
      sensor_msgs::PointCloud2 c = toCloud(sensor, mount, header);
      c.width = std::uint32_t(model.phiCount());
      c.height = std::uint32_t(model.psiCount());
      c.row_step = c.point_step * c.width;
      c.is_dense = false;
      clouds.push_back(std::move(c));
    }
    ROS_INFO("rate_feeder: %d sweeps of %u points ready; feeding at %.1f Hz for %.0f s", distinct,
             clouds.front().width * clouds.front().height, rate, duration);

    std::mutex mutex;
    std::vector<Status> statuses;
    ros::Subscriber sub = nh.subscribe<Status>(status_topic, 10000, [&](const Status::ConstPtr& s) {
      std::lock_guard<std::mutex> lock(mutex);
      statuses.push_back(*s);
    });
    ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("cloud", 1);
    tf2_ros::TransformBroadcaster tf_pub;
    ros::AsyncSpinner spinner(1);
    spinner.start();
    const ros::WallTime wait_end = ros::WallTime::now() + ros::WallDuration(wait_for_subscriber);
    while (ros::ok() && pub.getNumSubscribers() == 0 && ros::WallTime::now() < wait_end) {
      ros::WallDuration(0.05).sleep();
    }
    ros::WallDuration(1.0).sleep();  // the matcher's tf listener

    // Forward along the path and back: 0, 1, ..., n-1, n-2, ..., 1, 0, 1, ...
    const int n = int(clouds.size()), cycle = 2 * (n - 1);
    ros::Rate loop(rate);
    int published = 0;
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(duration);
    while (ros::ok() && ros::WallTime::now() < end) {
      const int phase = published % cycle, k = phase < n ? phase : cycle - phase;
      const ros::Time stamp = ros::Time::now();
      tf_pub.sendTransform(stampedTransform(poses[std::size_t(k)], "odom", "base_link", stamp));
      sensor_msgs::PointCloud2& c = clouds[std::size_t(k)];
      c.header.stamp = stamp;
      c.header.seq = std::uint32_t(published);
      pub.publish(c);
      ++published;
      loop.sleep();
    }
    ros::WallDuration(2.0).sleep();  // the last answers

    std::lock_guard<std::mutex> lock(mutex);
    std::vector<double> age, latency, registration;
    int accepted = 0;
    std::uint64_t ref_bytes = 0, work_bytes = 0, key_bytes = 0;
    std::uint32_t dropped = 0;
    for (const Status& s : statuses) {
      age.push_back(1e3 * s.data_age);
      latency.push_back(1e3 * s.latency);
      if (s.registration_time > 0.0) registration.push_back(1e3 * s.registration_time);
      accepted += s.accepted;
      ref_bytes = std::max<std::uint64_t>(ref_bytes, s.reference_bytes);
      work_bytes = std::max<std::uint64_t>(work_bytes, s.workspace_bytes);
      key_bytes = std::max<std::uint64_t>(key_bytes, s.keyframe_bytes);
      dropped = std::max(dropped, s.dropped_scans);
    }
    if (statuses.empty()) throw std::runtime_error("no status from " + status_topic + ": is the matcher running?");
    const auto mb = [](std::uint64_t b) { return double(b) / (1024.0 * 1024.0); };
    std::printf("rate_feeder: %.1f Hz for %.0f s, %u points per sweep (%s, %d distinct sweeps, %.1f m/s, %.0f deg/s)\n",
                rate, duration, clouds.front().width * clouds.front().height, scene_name.c_str(), n,
                speed, yaw_rate);
    std::printf("published %d, answered %zu (accepted %d), dropped by the matcher's queue %u, unanswered %d\n",
                published, statuses.size(), accepted, dropped, published - int(statuses.size()));
    std::printf("data age (stamp -> pose) [ms]: median %.1f, p95 %.1f, max %.1f\n", quantile(age, 0.5),
                quantile(age, 0.95), *std::max_element(age.begin(), age.end()));
    std::printf("latency (arrival -> pose) [ms]: median %.1f, p95 %.1f; registration [ms]: median %.1f, p95 %.1f\n",
                quantile(latency, 0.5), quantile(latency, 0.95),
                registration.empty() ? 0.0 : quantile(registration, 0.5),
                registration.empty() ? 0.0 : quantile(registration, 0.95));
    std::printf("memory (largest reported) [MB]: reference grids and planes %.1f, working copies %.1f, keyframe points %.1f\n",
                mb(ref_bytes), mb(work_bytes), mb(key_bytes));
    std::fflush(stdout);
    if (int(statuses.size()) < min_answered || ref_bytes == 0) {
      ROS_ERROR("rate_feeder: %zu answers (at least %d wanted), reference memory %llu bytes",
                statuses.size(), min_answered, static_cast<unsigned long long>(ref_bytes));
      return 2;
    }
  } catch (const std::exception& e) {
    ROS_FATAL("rate_feeder: %s", e.what());
    return 1;
  }
  return 0;
}
