// clouds_to_bag OUTPUT.bag (--dataset DIR | CLOUD... [--poses FILE]) [options]
// Writes real scans into a bag that launch/bag_replay.launch can replay: one PointCloud2 per
// cloud (in --frame, default base_link) at --rate, plus tf odom -> base_link at each cloud's
// stamp from the poses (a poses file, or the chain of a dataset folder's pairs.txt).
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>

#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include "cube_scan_matcher/io/cloud_io.h"
#include "cube_scan_matcher/io/dataset.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/transforms.h"
#include "cube_scan_matcher/sim/motion.h"
#include "arg_reader.h"

using namespace cube_scan_matcher;

namespace {

const char* kUsage =
    "usage: clouds_to_bag OUTPUT.bag (--dataset DIR | CLOUD... [--poses FILE]) [options]\n"
    "  --dataset DIR        a folder in the format of shared/data/README.md: its clouds in\n"
    "                       chain order, poses from chaining pairs.txt (the first target = origin)\n"
    "  --poses FILE         one line per CLOUD: tx ty tz qx qy qz qw = T_odom_base [m]; without\n"
    "                       poses (and without --dataset) no tf is written\n"
    "  --rate HZ            clouds per second (default 1)\n"
    "  --start S            stamp of the first cloud [s] (default 1000)\n"
    "  --topic NAME         cloud topic (default assembled_cloud)\n"
    "  --frame NAME         cloud and base frame (default base_link)\n"
    "  --odom-frame NAME    odometry frame (default odom)\n"
    "  --odometry-error T A add uniform errors of +-T [m] and +-A [deg] per parameter to each\n"
    "                       pose increment, so the matcher has to correct them (default 0 0)\n"
    "  --seed N             seed of those errors (default 1)\n";

}  // namespace

int main(int argc, char** argv) {
  tools::ArgReader r(argc, argv);
  if (argc < 2 || r.help()) {
    std::cout << kUsage;
    return argc < 2 ? 1 : 0;
  }
  try {
    const std::string output = r.positional();
    std::vector<std::string> clouds;
    std::vector<Eigen::Isometry3d> poses;
    std::string dataset, poses_file, topic = "assembled_cloud", frame = "base_link", odom_frame = "odom";
    double rate = 1.0, start = 1000.0, err_t = 0.0, err_a = 0.0;
    std::uint64_t seed = 1;
    while (r.more()) {
      if (r.option("--dataset", dataset) || r.option("--poses", poses_file) ||
          r.option("--rate", rate) || r.option("--start", start) || r.option("--topic", topic) ||
          r.option("--frame", frame) || r.option("--odom-frame", odom_frame) ||
          r.option("--seed", seed) ||
          r.optionWith("--odometry-error", 2, [&](const std::vector<std::string>& v) {
            err_t = io::parseNumber("--odometry-error", v[0]);
            err_a = io::parseNumber("--odometry-error", v[1]);
          }))
        continue;
      clouds.push_back(r.positional());
    }
    if (!(rate > 0.0)) throw std::invalid_argument("--rate must be > 0");
    if (!(start > 0.0)) throw std::invalid_argument("--start must be > 0 (a zero stamp means no time)");
    if (!dataset.empty()) {
      if (!clouds.empty() || !poses_file.empty())
        throw std::invalid_argument("--dataset replaces CLOUD... and --poses");
      // Chain the pairs: the first pair's target is the origin; a source's pose is its
      // target's pose times T_target_source.
      const auto pairs = io::readPairs(dataset);
      std::map<std::string, Eigen::Isometry3d> pose_of;
      clouds.push_back(pairs.front().target);
      pose_of[pairs.front().target] = Eigen::Isometry3d::Identity();
      for (bool grew = true; grew;) {
        grew = false;
        for (const auto& p : pairs) {
          if (pose_of.count(p.target) && !pose_of.count(p.source)) {
            pose_of[p.source] = pose_of[p.target] * p.T_target_source;
            clouds.push_back(p.source);
            grew = true;
          }
        }
      }
      for (const auto& c : clouds) poses.push_back(pose_of[c]);
    } else if (!poses_file.empty()) {
      std::ifstream in(poses_file);
      if (!in) throw std::runtime_error("cannot open poses file " + poses_file);
      std::string line;
      for (int n = 1; std::getline(in, line); ++n) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ls(line);
        Eigen::Isometry3d T;
        if (!io::readPose(ls, T)) {
          throw std::runtime_error(poses_file + ":" + std::to_string(n) +
                                   ": expected tx ty tz qx qy qz qw");
        }
        poses.push_back(T);
      }
      if (poses.size() != clouds.size()) {
        throw std::runtime_error(poses_file + " has " + std::to_string(poses.size()) +
                                 " poses for " + std::to_string(clouds.size()) + " clouds");
      }
    }
    if (clouds.empty()) throw std::invalid_argument("no cloud given");

    // Odometry errors on each increment (the first pose stays exact).
    if (!poses.empty() && (err_t > 0.0 || err_a > 0.0)) {
      std::mt19937_64 rng(seed);
      std::vector<Eigen::Isometry3d> noisy{poses[0]};
      for (std::size_t k = 1; k < poses.size(); ++k) {
        noisy.push_back(noisy.back() * (poses[k - 1].inverse() * poses[k]) *
                        sim::randomTransform(rng, err_t, err_a));
      }
      poses = noisy;
    }

    rosbag::Bag bag(output, rosbag::bagmode::Write);
    for (std::size_t k = 0; k < clouds.size(); ++k) {
      const ros::Time stamp(start + double(k) / rate);
      const PointArray pts = io::readCloudFile(clouds[k]);
      std_msgs::Header header;
      header.stamp = stamp;
      header.frame_id = frame;
      header.seq = std::uint32_t(k);
      if (!poses.empty()) {
        tf2_msgs::TFMessage tf;
        tf.transforms.push_back(stampedTransform(poses[k], odom_frame, frame, stamp));
        bag.write("/tf", stamp - ros::Duration(0.001), tf);  // tf just before its cloud
      }
      bag.write("/" + topic, stamp, toCloud(pts, Eigen::Isometry3d::Identity(), header));
      std::cout << clouds[k] << ": " << pts.size() << " points at " << stamp.toSec() << " s\n";
    }
    bag.close();
    std::cout << "wrote " << clouds.size() << " clouds" << (poses.empty() ? "" : " and tf") << " to "
              << output << "\n";
  } catch (const std::exception& e) {
    std::cerr << "clouds_to_bag: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
