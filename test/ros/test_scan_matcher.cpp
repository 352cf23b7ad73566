// rostest for ScanMatcherNodelet, run twice: under scan_matcher_node (node .test) and loaded
// into a nodelet manager (nodelet .test). It publishes simulated tilting-scanner sweeps of a
// known scene with tf odom -> base_link carrying a known odometry error, and checks the
// published poses against the truth, the frames and stamps of every output, and the handling
// of bad input.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_srvs/Trigger.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"
#include "cube_scan_matcher/ros/params.h"
#include "cube_scan_matcher/ros/transforms.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "expect_params.h"
#include "ros_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

WorstError worst;  // printed at exit

namespace {

const std::string kNs = "/scan_matcher/";

class ScanMatcherRos : public ::testing::Test {
 protected:
  ros::NodeHandle nh;
  ros::Publisher cloud_pub = nh.advertise<sensor_msgs::PointCloud2>("/test_cloud", 10);
  tf2_ros::TransformBroadcaster tf_pub;
  tf2_ros::StaticTransformBroadcaster static_pub;
  Outputs out{nh, kNs};

  void SetUp() override {
    ASSERT_TRUE(waitFor([&] { return cloud_pub.getNumSubscribers() > 0; }, 30.0))
        << "the scan matcher did not subscribe to /test_cloud";
    ASSERT_TRUE(ros::service::waitForService(kNs + "reset", ros::Duration(10.0)));
    std_srvs::Trigger reset;
    ASSERT_TRUE(ros::service::call(kNs + "reset", reset));
    waitFor([] { return false; }, 0.3);  // let subscriptions connect
  }

  /// Publishes `cloud` and waits for its status.
  Status send(const sensor_msgs::PointCloud2& cloud) {
    const std::size_t n = out.status.size();
    cloud_pub.publish(cloud);
    EXPECT_TRUE(waitFor([&] { return out.status.size() > n; }, 20.0)) << "no status for a cloud";
    return out.status.empty() ? Status{} : out.status.back();
  }
};

// config/scan_matcher.yaml, loaded by the .test files, holds the code's defaults (the .test
// files override tf_timeout only).
TEST(ScanMatcherYaml, LoadsAndEqualsTheDefaults) {
  NodeParams p;
  ASSERT_NO_THROW(p = loadParams(ros::NodeHandle(kNs)));
  expectSameLiveParams(toConfig(p), toConfig(NodeParams{}));
  EXPECT_EQ(p.base_frame, "base_link");
  EXPECT_EQ(p.queue_size, 1);
  EXPECT_EQ(p.path_max_length, NodeParams{}.path_max_length);
  EXPECT_DOUBLE_EQ(p.sigma_translation, NodeParams{}.sigma_translation);
}

TEST_F(ScanMatcherRos, RegistersSimulatedSweepsToTheTruth) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  const sim::ScannerModel model;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  mount.translation() = Eigen::Vector3d(0.2, 0.0, 0.5);
  static_pub.sendTransform(stampedTransform(mount, "base_link", "laser", ros::Time(0)));

  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity(), odom = Eigen::Isometry3d::Identity();
  truth.linear() = rotationFromRpy(0.01, -0.01, deg2rad(17));
  truth.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  odom = truth;  // map = odom at the first scan
  const ros::Time t0 = ros::Time::now();
  std::vector<Eigen::Isometry3d> truths;
  for (int k = 0; k < 3; ++k) {
    if (k > 0) {
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      step.translation() = Eigen::Vector3d(2.0 + 0.5 * u(rng), 0.3 * u(rng), 0.0);
      step.linear() = rotationFromRpy(0.0, 0.0, deg2rad(10.0 * u(rng)));
      Eigen::Isometry3d next = truth * step;
      next.translation().z() = scene.groundHeight(next.translation().x(), next.translation().y()) + 0.5;
      // Odometry drifts: the true increment times an error of up to 0.3 m / 3 deg.
      Eigen::Isometry3d err = Eigen::Isometry3d::Identity();
      err.translation() = 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      err.linear() = rotationFromRpy(deg2rad(3 * u(rng)), deg2rad(3 * u(rng)), deg2rad(3 * u(rng)));
      odom = odom * (truth.inverse() * next) * err;
      truth = next;
    }
    truths.push_back(truth);
    const ros::Time stamp = t0 + ros::Duration(0.5 * (k + 1));
    tf_pub.sendTransform(stampedTransform(odom, "odom", "base_link", stamp));
    waitFor([] { return false; }, 0.2);  // tf reaches the matcher before the cloud
    const PointArray pts = sim::scan(scene, model, truth * mount, rng);
    const Status s = send(makeCloud(pts, "laser", stamp));
    EXPECT_EQ(s.header.stamp, stamp);
    EXPECT_EQ(s.header.frame_id, "map");
    EXPECT_EQ(s.reason, k == 0 ? Status::FIRST_SCAN : Status::ACCEPTED) << s.message;
    EXPECT_FALSE(s.tf_failed);
    EXPECT_EQ(s.points_in, pts.size());
    if (k > 0) {
      EXPECT_TRUE(s.odometry_guess);
    }
  }
  ASSERT_TRUE(waitFor([&] { return out.pose.size() >= 3 && out.odom.size() >= 3 &&
                                   out.cloud.size() >= 3 && out.path.poses.size() >= 3; }, 10.0));
  for (int k = 0; k < 3; ++k) {
    const auto& p = out.pose[std::size_t(out.pose.size() - 3 + k)];
    EXPECT_EQ(p.header.frame_id, "map");
    EXPECT_EQ(p.header.stamp, t0 + ros::Duration(0.5 * (k + 1)));
    Eigen::Isometry3d est;
    tf2::fromMsg(p.pose.pose, est);
    // Expected: the first odometry pose, then the true increments.
    const Eigen::Isometry3d expected = truths[0] * (truths[0].inverse() * truths[std::size_t(k)]);
    const Eigen::Isometry3d e = expected.inverse() * est;
    worst.add(e);
    // Measured up to 2.0 mm / 0.0057 deg: the limits are twice that.
    EXPECT_LT(e.translation().norm(), 0.004) << "scan " << k;
    EXPECT_LT(rad2deg(Eigen::AngleAxisd(e.linear()).angle()), 0.011) << "scan " << k;
    EXPECT_GT(p.pose.covariance[0], 0.0);
    if (k > 0) {  // the covariance grows along the chain
      EXPECT_GT(p.pose.covariance[0], out.pose[out.pose.size() - 4 + std::size_t(k)].pose.covariance[0]);
    }
  }
  const auto& o = out.odom.back();
  {
    // Twist: the mean velocity over the last increment (0.5 s), in base_link at the scan.
    const Eigen::Isometry3d inc = truths[1].inverse() * truths[2];
    const Eigen::Vector3d v = inc.linear().transpose() * inc.translation() / 0.5;
    const auto& tw = o.twist.twist;
    EXPECT_LT((Eigen::Vector3d(tw.linear.x, tw.linear.y, tw.linear.z) - v).norm(), 0.15);
    const Eigen::AngleAxisd aa(inc.linear());
    EXPECT_NEAR(tw.angular.z, aa.angle() * aa.axis().z() / 0.5, 0.02);
    EXPECT_GT(o.twist.covariance[0], 0.0);
  }
  EXPECT_EQ(o.header.frame_id, "map");
  EXPECT_EQ(o.child_frame_id, "base_link");
  EXPECT_EQ(o.header.stamp, t0 + ros::Duration(1.5));
  EXPECT_EQ(out.cloud.back().header.frame_id, "map");
  EXPECT_EQ(out.cloud.back().header.stamp, t0 + ros::Duration(1.5));
  EXPECT_GT(out.cloud.back().width, 1000u);
  EXPECT_EQ(out.path.header.frame_id, "map");
  EXPECT_EQ(out.path.poses.size(), 3u);
}

TEST_F(ScanMatcherRos, BadInputKeepsTheNodeAliveAndIsReported) {
  // A good reference first (cloud in base_link, odometry identity).
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Hall, 2);
  std::mt19937_64 rng(3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(2, 1, 1);
  body.linear() = rotationFromRpy(0, 0, deg2rad(17));
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  PointArray good = sim::scan(scene, sim::ScannerModel{}, body * mount, rng);
  for (std::size_t i = 0; i < good.size(); ++i) {  // into base_link
    const Eigen::Vector3f p = mount.cast<float>() * good.point(i);
    good.x[i] = p.x(), good.y[i] = p.y(), good.z[i] = p.z();
  }
  ros::Time stamp = ros::Time::now();
  auto next = [&] {
    stamp += ros::Duration(0.5);
    tf_pub.sendTransform(stampedTransform(Eigen::Isometry3d::Identity(), "odom", "base_link", stamp));
    waitFor([] { return false; }, 0.1);
    return stamp;
  };
  EXPECT_EQ(send(makeCloud(good, "base_link", next())).reason, Status::FIRST_SCAN);

  // Empty cloud.
  Status s = send(makeCloud(PointArray{}, "base_link", next()));
  EXPECT_EQ(s.reason, Status::BAD_INPUT);
  EXPECT_NE(s.message.find("no usable point"), std::string::npos) << s.message;

  // All-NaN cloud.
  PointArray nan;
  for (int i = 0; i < 100; ++i) nan.push_back(NAN, NAN, NAN);
  s = send(makeCloud(nan, "base_link", next()));
  EXPECT_EQ(s.reason, Status::BAD_INPUT);
  EXPECT_NE(s.message.find("100 NaN"), std::string::npos) << s.message;

  // No x/y/z fields.
  sensor_msgs::PointCloud2 noxyz;
  noxyz.header.frame_id = "base_link";
  noxyz.header.stamp = next();
  sensor_msgs::PointCloud2Modifier(noxyz).setPointCloud2FieldsByString(1, "rgb");
  sensor_msgs::PointCloud2Modifier(noxyz).resize(10);
  s = send(noxyz);
  EXPECT_EQ(s.reason, Status::BAD_INPUT);
  EXPECT_NE(s.message.find("no x/y/z"), std::string::npos) << s.message;

  // float64 x/y/z: read and registered like float32.
  sensor_msgs::PointCloud2 f64;
  f64.header.frame_id = "base_link";
  f64.header.stamp = next();
  sensor_msgs::PointCloud2Modifier(f64).setPointCloud2Fields(
      3, "x", 1, sensor_msgs::PointField::FLOAT64, "y", 1, sensor_msgs::PointField::FLOAT64, "z",
      1, sensor_msgs::PointField::FLOAT64);
  sensor_msgs::PointCloud2Modifier(f64).resize(good.size());
  {
    sensor_msgs::PointCloud2Iterator<double> x(f64, "x"), y(f64, "y"), z(f64, "z");
    for (std::size_t i = 0; i < good.size(); ++i, ++x, ++y, ++z) *x = good.x[i], *y = good.y[i], *z = good.z[i];
  }
  s = send(f64);
  EXPECT_EQ(s.reason, Status::ACCEPTED) << s.message;
  EXPECT_EQ(s.points_valid, good.size());

  // Absurd coordinates: the grid's memory cap refuses the scan as a reference (it moved 1.1 m,
  // beyond keyframe_distance, so it would be the next keyframe), nothing crashes.
  PointArray absurd;
  for (std::size_t i = 0; i < good.size(); ++i) absurd.push_back(good.x[i] - 1.1f, good.y[i], good.z[i]);
  absurd.push_back(1e6f, 1e6f, 1e6f);
  s = send(makeCloud(absurd, "base_link", next()));
  EXPECT_FALSE(s.reference_updated);
  EXPECT_NE(s.message.find("not used as reference"), std::string::npos) << s.message;

  // Missing tf: a stamp with no odometry, registered from an identity guess and flagged.
  stamp += ros::Duration(0.5);
  s = send(makeCloud(good, "base_link", stamp));
  EXPECT_TRUE(s.tf_failed);
  EXPECT_FALSE(s.odometry_guess);
  EXPECT_GE(s.tf_failures, 1u);

  // A cloud in a frame tf does not know: skipped and counted.
  s = send(makeCloud(good, "no_such_frame", next()));
  EXPECT_EQ(s.reason, Status::SKIPPED_NO_TF);

  // Clock jumps backwards: one reset, the scan starts a new chain at its odometry.
  stamp -= ros::Duration(5.0);
  tf_pub.sendTransform(stampedTransform(Eigen::Isometry3d::Identity(), "odom", "base_link", stamp));
  waitFor([] { return false; }, 0.1);
  s = send(makeCloud(good, "base_link", stamp));
  EXPECT_TRUE(s.time_reset);
  EXPECT_FALSE(s.tf_failed);
  EXPECT_EQ(s.reason, Status::FIRST_SCAN) << s.message;

  // The node is still alive and registering.
  stamp = ros::Time::now() + ros::Duration(1.0);
  s = send(makeCloud(good, "base_link", next()));
  EXPECT_EQ(s.reason, Status::ACCEPTED) << s.message;
}

// Run alone with a bad parameter (test/ros/bad_param.test): the matcher refuses to start and
// names the parameter (log and diagnostics at ERROR), and the process (the manager) stays up.
TEST(ScanMatcherBadParam, RefusesToStartAndNamesTheParameter) {
  ros::NodeHandle nh;
  std::vector<diagnostic_msgs::DiagnosticStatus> diagnostics;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status) diagnostics.push_back(s);
      });
  ASSERT_TRUE(waitFor([&] {
    for (const auto& d : diagnostics) {
      if (d.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
          d.message.find("~cube_edge") != std::string::npos) {
        return true;
      }
    }
    return false;
  }, 30.0)) << "no ERROR diagnostic naming ~cube_edge";
  ros::V_string nodes;
  ros::master::getNodes(nodes);
  std::string manager;
  ros::param::get("~manager_node", manager);
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), manager), nodes.end()) << manager << " went down";
  EXPECT_FALSE(ros::service::exists(kNs + "reset", false));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_scan_matcher");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
