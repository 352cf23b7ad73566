// rostest for ScanMatcherNodelet, run twice: under scan_matcher_node (node .test) and loaded
// into a nodelet manager (nodelet .test). It publishes simulated tilting-scanner sweeps of a
// known scene with tf odom -> base_link carrying a known odometry error, and checks the
// published poses against the truth, the frames and stamps of every output, and the handling
// of bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
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
#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "cube_scan_matcher/SetPose.h"
#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/pose_covariance.h"
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

/// A simulated sweep of `scene` from the body pose `body`, its points in base_link (the laser
/// at base_link's origin, turned by sim::sensorToBodyRotation).
PointArray sweepInBase(const sim::Scene& scene, const Eigen::Isometry3d& body, std::mt19937_64& rng) {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  PointArray pts = sim::scan(scene, sim::ScannerModel{}, body * mount, rng);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3f p = mount.cast<float>() * pts.point(i);
    pts.x[i] = p.x(), pts.y[i] = p.y(), pts.z[i] = p.z();
  }
  return pts;
}

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

  /// A robot driving 0.5 m per scan along its x axis in `scene` from `body`: the scans
  /// registered, the odometry on tf as `odom_of(k, truth)`. Returns each scan's stamp.
  template <typename OdomOf>
  std::vector<ros::Time> driveStraight(const sim::Scene& scene, Eigen::Isometry3d body, int scans,
                                       OdomOf odom_of, std::vector<Status>* statuses) {
    std::mt19937_64 rng(21);
    std::vector<ros::Time> stamps;
    ros::Time stamp = ros::Time::now();
    for (int k = 0; k < scans; ++k) {
      if (k > 0) {
        body.translation() += 0.5 * body.linear().col(0);
        body.translation().z() = scene.groundHeight(body.translation().x(), body.translation().y()) + 0.5;
      }
      stamp += ros::Duration(0.5);
      tf_pub.sendTransform(stampedTransform(odom_of(k, body), "odom", "base_link", stamp));
      waitFor([] { return false; }, 0.1);
      statuses->push_back(send(makeCloud(sweepInBase(scene, body, rng), "base_link", stamp)));
      stamps.push_back(stamp);
    }
    return stamps;
  }
};

/// The matcher with role anchored (test/ros/anchored.test).
class ScanMatcherAnchored : public ScanMatcherRos {};

// config/scan_matcher.yaml, loaded by the .test files, holds the code's defaults (the .test
// files override tf_timeout only).
TEST(ScanMatcherYaml, LoadsAndEqualsTheDefaults) {
  NodeParams p;
  ASSERT_NO_THROW(p = loadParams(ros::NodeHandle(kNs)));
  expectSameLiveParams(toConfig(p), toConfig(NodeParams{}));
  EXPECT_EQ(p.base_frame, "base_link");
  EXPECT_EQ(p.queue_size, 1);
  EXPECT_EQ(p.path_max_length, NodeParams{}.path_max_length);
  EXPECT_DOUBLE_EQ(p.chain.sigma_m, NodeParams{}.chain.sigma_m);
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
  const PointArray good = sweepInBase(scene, body, rng);
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

/// The odometry message published for the cloud stamped `stamp`, waiting up to 10 s.
const nav_msgs::Odometry* odometryAt(Outputs& out, const ros::Time& stamp) {
  const nav_msgs::Odometry* found = nullptr;
  waitFor([&] {
    for (const auto& o : out.odom) {
      if (o.header.stamp == stamp) found = &o;
    }
    return found != nullptr;
  }, 10.0);
  return found;
}

/// A twist a filter can fuse: every variance positive and finite; `unknown`: zero velocity with
/// kUnknownTwistVariance on every diagonal entry and nothing off it.
void expectFusableTwist(const nav_msgs::Odometry& o, bool unknown, const std::string& what) {
  for (int i = 0; i < 6; ++i) {
    const double var = o.twist.covariance[std::size_t(7 * i)];
    EXPECT_TRUE(std::isfinite(var) && var > 0.0) << what << ": twist variance " << i << " = " << var;
    for (int j = 0; j < 6; ++j) {
      EXPECT_EQ(o.twist.covariance[std::size_t(6 * i + j)], o.twist.covariance[std::size_t(6 * j + i)])
          << what << ": not symmetric";
      if (unknown && i != j) {
        EXPECT_EQ(o.twist.covariance[std::size_t(6 * i + j)], 0.0) << what;
      }
    }
    if (unknown) {
      EXPECT_EQ(var, kUnknownTwistVariance) << what << ": variance " << i;
    } else {
      EXPECT_LT(var, kUnknownTwistVariance) << what << ": variance " << i << " of a known twist";
    }
  }
  const auto& t = o.twist.twist;
  if (unknown) {
    EXPECT_EQ(t.linear.x, 0.0) << what;
    EXPECT_EQ(t.linear.y, 0.0) << what;
    EXPECT_EQ(t.angular.z, 0.0) << what;
  }
}

// ~odometry on a first, an accepted and a rejected scan: a twist is known only after an
// accepted registration; otherwise it is published as unknown (never a zero or negative
// variance, which robot_localization would read as a certain zero velocity).
TEST_F(ScanMatcherRos, OdometryTwistIsFusableOnEveryScan) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(5);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.linear() = rotationFromRpy(0.0, 0.0, deg2rad(17));
  body.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  auto scanAt = [&](const Eigen::Isometry3d& b) { return sweepInBase(scene, b, rng); };
  auto ahead = [&](const Eigen::Isometry3d& b, double metres) {  // along the body's x axis
    Eigen::Isometry3d n = b;
    n.translation() += metres * b.linear().col(0);
    n.translation().z() = scene.groundHeight(n.translation().x(), n.translation().y()) + 0.5;
    return n;
  };
  ros::Time stamp = ros::Time::now();
  // Odometry = truth; the robot drives 0.5 m along x per 0.5 s (1 m/s).
  auto sendAt = [&](const Eigen::Isometry3d& odom, const PointArray& pts) {
    stamp += ros::Duration(0.5);
    tf_pub.sendTransform(stampedTransform(odom, "odom", "base_link", stamp));
    waitFor([] { return false; }, 0.1);
    const Status s = send(makeCloud(pts, "base_link", stamp));
    const nav_msgs::Odometry* o = odometryAt(out, stamp);
    EXPECT_NE(o, nullptr) << "no ~odometry for the scan at " << stamp;
    return std::make_pair(s, o ? *o : nav_msgs::Odometry{});
  };
  auto [first, o_first] = sendAt(body, scanAt(body));
  EXPECT_EQ(first.reason, Status::FIRST_SCAN) << first.message;
  expectFusableTwist(o_first, true, "first scan");

  Eigen::Isometry3d moved = ahead(body, 0.5);
  auto [accepted, o_accepted] = sendAt(moved, scanAt(moved));
  EXPECT_EQ(accepted.reason, Status::ACCEPTED) << accepted.message;
  expectFusableTwist(o_accepted, false, "accepted scan");
  EXPECT_NEAR(o_accepted.twist.twist.linear.x, 1.0, 0.05);
  // The motion model's error: the first twist after a chain's start changed from an unknown
  // one, taken as 0, so its variance holds the whole velocity squared.
  EXPECT_GT(o_accepted.twist.covariance[0], 0.9);

  // The scan shows the robot 5 m further than the odometry says: beyond the gate's correction
  // bound, so rejected, and its twist is unknown.
  const Eigen::Isometry3d far = ahead(moved, 5.5);
  moved = ahead(moved, 0.5);
  auto [rejected, o_rejected] = sendAt(moved, scanAt(far));
  EXPECT_NE(rejected.reason, Status::ACCEPTED) << rejected.message;
  EXPECT_NE(rejected.reason, Status::FIRST_SCAN) << rejected.message;
  EXPECT_NE(rejected.reason, Status::BAD_INPUT) << rejected.message;
  expectFusableTwist(o_rejected, true, "rejected scan");

  // Accepted again at the same speed: the change from the last known twist is small now.
  moved = ahead(moved, 0.5);
  auto [again, o_again] = sendAt(moved, scanAt(moved));
  EXPECT_EQ(again.reason, Status::ACCEPTED) << again.message;
  expectFusableTwist(o_again, false, "accepted scan after a rejection");
  EXPECT_NEAR(o_again.twist.twist.linear.x, 1.0, 0.05);
  EXPECT_LT(o_again.twist.covariance[0], 0.05);
}

// RViz's "2D Pose Estimate" on /initialpose: the next scan starts a new chain at the given x,
// y and yaw, keeping the last pose's z, roll and pitch; a pose in another frame is refused.
TEST_F(ScanMatcherRos, InitialPoseRestartsTheChainOnTheGroundPlane) {
  ros::Publisher initial = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("/initialpose", 1);
  ASSERT_TRUE(waitFor([&] { return initial.getNumSubscribers() > 0; }, 10.0))
      << "the scan matcher did not subscribe to /initialpose";
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(9);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.linear() = rotationFromRpy(0.02, -0.03, deg2rad(17));
  body.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  const PointArray pts = sweepInBase(scene, body, rng);
  ros::Time stamp = ros::Time::now();
  auto sendScan = [&] {
    stamp += ros::Duration(0.5);
    tf_pub.sendTransform(stampedTransform(body, "odom", "base_link", stamp));
    waitFor([] { return false; }, 0.1);
    return send(makeCloud(pts, "base_link", stamp));
  };
  EXPECT_EQ(sendScan().reason, Status::FIRST_SCAN);  // the chain starts at the odometry pose
  EXPECT_EQ(sendScan().reason, Status::ACCEPTED);

  auto publishInitial = [&](const std::string& frame) {
    geometry_msgs::PoseWithCovarianceStamped m;
    m.header.frame_id = frame;
    m.header.stamp = ros::Time::now();
    m.pose.pose.position.x = 10.0, m.pose.pose.position.y = -4.0;  // z 0, level: as RViz sends
    const Eigen::Quaterniond q(Eigen::AngleAxisd(deg2rad(-60), Eigen::Vector3d::UnitZ()));
    m.pose.pose.orientation.w = q.w(), m.pose.pose.orientation.z = q.z();
    m.pose.covariance[0] = m.pose.covariance[7] = 0.25;  // RViz's 0.5 m
    initial.publish(m);
    waitFor([] { return false; }, 0.5);
  };
  publishInitial("not_the_map");  // refused: the chain goes on
  EXPECT_EQ(sendScan().reason, Status::ACCEPTED);

  publishInitial("map");
  const Status s = sendScan();
  EXPECT_EQ(s.reason, Status::FIRST_SCAN) << s.message;
  ASSERT_TRUE(waitFor([&] { return !out.pose.empty() && out.pose.back().header.stamp == stamp; }, 10.0));
  const auto& p = out.pose.back();
  Eigen::Isometry3d est;
  tf2::fromMsg(p.pose.pose, est);
  EXPECT_NEAR(est.translation().x(), 10.0, 1e-9);
  EXPECT_NEAR(est.translation().y(), -4.0, 1e-9);
  EXPECT_NEAR(est.translation().z(), body.translation().z(), 0.01);  // kept, not RViz's 0
  const Eigen::Matrix3d expected =
      rotationFromRpy(0.0, 0.0, deg2rad(-60)) * rotationFromRpy(0.0, 0.0, deg2rad(17)).transpose() *
      body.linear();  // the given yaw, the last pose's roll and pitch
  EXPECT_LT(rad2deg(Eigen::AngleAxisd(expected.transpose() * est.linear()).angle()), 0.5);
  EXPECT_NEAR(p.pose.covariance[0], 0.25, 1e-12);  // given
  EXPECT_GT(p.pose.covariance[14], 0.0);            // z: the configured sigma, not RViz's 0
}

// ~registered_cloud keeps each valid point's intensity (a point dropped as invalid takes its
// intensity with it), as float32 "intensity".
TEST_F(ScanMatcherRos, RegisteredCloudCarriesTheIntensityOfEachValidPoint) {
  std::optional<sensor_msgs::PointCloud2> registered;
  ros::Subscriber sub = nh.subscribe<sensor_msgs::PointCloud2>(
      kNs + "registered_cloud", 5,
      [&](const sensor_msgs::PointCloud2::ConstPtr& m) { registered = *m; });
  ASSERT_TRUE(waitFor([&] { return sub.getNumPublishers() > 0; }, 10.0));
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(13);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  PointArray pts;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pts.push_back(nan, nan, nan);  // no return: dropped
  const PointArray sweep = sweepInBase(scene, body, rng);
  for (std::size_t i = 0; i < sweep.size(); ++i) pts.push_back(sweep.x[i], sweep.y[i], sweep.z[i]);
  std::vector<float> intensity(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) intensity[i] = float(i % 1000);
  const ros::Time stamp = ros::Time::now();
  tf_pub.sendTransform(stampedTransform(body, "odom", "base_link", stamp));
  waitFor([] { return false; }, 0.1);
  std_msgs::Header h;
  h.frame_id = "base_link";
  h.stamp = stamp;
  send(toCloud(pts, Eigen::Isometry3d::Identity(), h, &intensity));
  ASSERT_TRUE(waitFor([&] { return registered && registered->header.stamp == stamp; }, 10.0));
  ASSERT_EQ(registered->width, sweep.size());
  sensor_msgs::PointCloud2ConstIterator<float> in(*registered, "intensity"), x(*registered, "x");
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < sweep.size(); ++i, ++in) wrong += *in != float((i + 1) % 1000);
  EXPECT_EQ(wrong, 0u) << "intensities out of step with their points";
  EXPECT_TRUE(std::isfinite(*x));
}

// role messages (the shipped default): poses and odometry on topics, no map -> odom on tf, so
// that nothing clashes with another localizer.
TEST_F(ScanMatcherRos, MessagesRoleSendsNoTf) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  std::vector<Status> statuses;
  driveStraight(scene, body, 3, [](int, const Eigen::Isometry3d& b) { return b; }, &statuses);
  EXPECT_EQ(statuses.back().reason, Status::ACCEPTED) << statuses.back().message;
  waitFor([] { return false; }, 1.0);
  EXPECT_FALSE(buffer._frameExists("map")) << "map -> odom published with role messages";
  EXPECT_FALSE(out.pose.empty());
}

// role anchored (test/ros/anchored.test): the odometry drifts sideways by 5 cm per scan while
// the scans show a straight drive. The published pose is the chain pulled towards the
// odometry: between the two, and map -> odom on tf matches it.
TEST_F(ScanMatcherAnchored, PullsTheChainTowardsTheOdometry) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(3, 1, scene.groundHeight(3, 1) + 0.5);
  auto odom_of = [&](int k, const Eigen::Isometry3d& b) {
    Eigen::Isometry3d o = b;
    o.translation().y() += 0.05 * k;
    return o;
  };
  std::vector<Status> statuses;
  const int n = 8;
  const std::vector<ros::Time> stamps = driveStraight(scene, body, n, odom_of, &statuses);
  for (int k = 1; k < n; ++k) EXPECT_EQ(statuses[std::size_t(k)].reason, Status::ACCEPTED) << k;
  ASSERT_TRUE(waitFor([&] { return !out.pose.empty() && out.pose.back().header.stamp == stamps.back(); }, 10.0));
  Eigen::Isometry3d first, last;
  tf2::fromMsg(out.pose.front().pose.pose, first);
  tf2::fromMsg(out.pose.back().pose.pose, last);
  // The first pose is the odometry's (0 offset); the last lies between the chain (y = 1, the
  // scans') and the odometry (y = 1.35), strictly.
  EXPECT_NEAR(first.translation().y(), 1.0, 1e-6);
  const double y = last.translation().y();
  EXPECT_GT(y, 1.0 + 0.01) << "not pulled towards the odometry";
  EXPECT_LT(y, 1.0 + 0.05 * (n - 1) - 0.01) << "the chain's motion ignored";
  // map -> odom: map -> odom -> base_link is the published pose.
  ASSERT_TRUE(waitFor([&] { return buffer.canTransform("map", "odom", ros::Time(0)); }, 5.0));
  const Eigen::Isometry3d map_odom = tf2::transformToEigen(buffer.lookupTransform("map", "odom", ros::Time(0)));
  Eigen::Isometry3d odom_last = Eigen::Isometry3d::Identity();
  tf2::fromMsg(out.odom.back().pose.pose, odom_last);
  EXPECT_LT((odom_last.inverse() * last).translation().norm(), 1e-9);  // the same pose on both
  Eigen::Isometry3d truth_last = body;
  truth_last.translation() += 0.5 * (n - 1) * body.linear().col(0);
  truth_last.translation().z() =
      scene.groundHeight(truth_last.translation().x(), truth_last.translation().y()) + 0.5;
  const Eigen::Isometry3d expected = map_odom * odom_of(n - 1, truth_last);
  EXPECT_LT((expected.inverse() * last).translation().norm(), 1e-3);
}

// Run alone with a bad parameter (test/ros/bad_param.test): the matcher refuses to start and
// names the parameter (log and diagnostics at ERROR), and the process (the manager) stays up.
TEST(ScanMatcherBadParam, RefusesToStartAndNamesTheParameter) {
  ros::NodeHandle nh;
  std::vector<diagnostic_msgs::DiagnosticStatus> diagnostics;
  const ros::Subscriber sub = collectDiagnostics(nh, diagnostics);
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

/// The matcher configured without odometry (test/ros/no_odometry.test: odom_frame "").
class ScanMatcherNoOdometry : public ScanMatcherRos {};

// No odometry on tf and none configured: no scan waits the 5 s tf_timeout or counts a tf
// failure, and each is registered from the prediction (the robot stands still between scans
// 0.2 m apart, well within the search bounds).
TEST_F(ScanMatcherNoOdometry, RegistersFromThePredictionWithoutWaitingForTf) {
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::mt19937_64 rng(5);
  ros::Time stamp = ros::Time::now();
  for (int k = 0; k < 4; ++k) {
    body.translation() += 0.2 * body.linear().col(0);
    body.translation().z() = scene.groundHeight(body.translation().x(), body.translation().y()) + 0.5;
    stamp += ros::Duration(0.5);
    const Status s = send(makeCloud(sweepInBase(scene, body, rng), "base_link", stamp));
    EXPECT_FALSE(s.tf_failed) << "scan " << k;
    EXPECT_FALSE(s.odometry_guess) << "scan " << k;
    EXPECT_LT(s.latency, 4.0) << "scan " << k << " waited for an odometry tf";
    EXPECT_NE(s.reason, Status::SKIPPED_NO_TF) << "scan " << k;
    EXPECT_NE(s.reason, Status::NON_FINITE) << "scan " << k;
  }
  ASSERT_EQ(out.status.size(), 4u);
  EXPECT_EQ(out.status[0].reason, Status::FIRST_SCAN);
  EXPECT_GE(std::count_if(out.status.begin() + 1, out.status.end(),
                          [](const Status& s) { return s.accepted; }), 2)
      << "scans 1-3 registered from the prediction";
  ASSERT_FALSE(out.pose.empty());
  EXPECT_EQ(out.pose.back().header.frame_id, "map");
}

// test/ros/param_names.test: a misspelt name is a WARN naming it and the closest known name
// (the nodelet runs); a renamed one refuses the start with the new name.
TEST(ScanMatcherParamNames, MisspeltIsWarnedAndRenamedIsRefused) {
  ros::NodeHandle nh;
  std::vector<diagnostic_msgs::DiagnosticStatus> diagnostics;
  const ros::Subscriber sub = collectDiagnostics(nh, diagnostics);
  auto seen = [&](const std::string& node, std::uint8_t level, const std::string& text) {
    for (const auto& d : diagnostics) {
      if (d.name.find(node) == std::string::npos || d.level != level) continue;
      if (d.message.find(text) != std::string::npos) return true;
      for (const auto& kv : d.values) {
        if (kv.value.find(text) != std::string::npos) return true;
      }
    }
    return false;
  };
  using diagnostic_msgs::DiagnosticStatus;
  EXPECT_TRUE(waitFor([&] {
    return seen("misspelt", DiagnosticStatus::WARN, "did you mean ~keyframe_distance?");
  }, 30.0)) << "no WARN naming ~keyframe_distanse's closest name";
  EXPECT_TRUE(ros::service::exists("/misspelt/reset", false)) << "the misspelt one must run";
  EXPECT_TRUE(waitFor([&] {
    return seen("renamed", DiagnosticStatus::ERROR, "~keyframe_angle is now called ~keyframe_angle_deg");
  }, 30.0)) << "no ERROR naming the new name of ~keyframe_angle";
  EXPECT_FALSE(ros::service::exists("/renamed/reset", false));
  EXPECT_TRUE(waitFor([&] {
    return seen("assembler", DiagnosticStatus::WARN, "did you mean ~tilt_axis?");
  }, 30.0)) << "no WARN from the assembler naming ~tilt_axes's closest name";
}

/// The matcher with search settings that make one registration last seconds
/// (test/ros/slow_registration.test).
class ScanMatcherSlow : public ScanMatcherRos {};

// While a registration runs, the nodelet still answers: a service within 100 ms, diagnostics
// every second, map -> odom at tf_rate; clouds that arrive meanwhile are not queued behind it
// (the newest waits in the mailbox, older ones are dropped and counted).
TEST_F(ScanMatcherSlow, ServicesDiagnosticsAndTfAnswerWhileARegistrationRuns) {
  std::vector<double> diagnostics_at, map_odom_at;  // wall times of arrival [s]
  ros::Subscriber diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& d : m->status) {
          if (d.name.find("registration") != std::string::npos) {
            diagnostics_at.push_back(ros::WallTime::now().toSec());
          }
        }
      });
  ros::Subscriber tf_sub = nh.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100, [&](const tf2_msgs::TFMessage::ConstPtr& m) {
        for (const auto& t : m->transforms) {
          if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
            map_odom_at.push_back(ros::WallTime::now().toSec());
          }
        }
      });
  double tf_rate = 0.0;
  ASSERT_TRUE(ros::param::get(kNs + "tf_rate", tf_rate));
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(31);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(0, 0, scene.groundHeight(0, 0) + 0.5);
  ros::Time stamp = ros::Time::now();
  auto cloudAt = [&](double ahead) {
    body.translation().x() += ahead;
    stamp += ros::Duration(0.5);
    tf_pub.sendTransform(stampedTransform(body, "odom", "base_link", stamp));
    return makeCloud(sweepInBase(scene, body, rng), "base_link", stamp);
  };
  EXPECT_EQ(send(cloudAt(0.0)).reason, Status::FIRST_SCAN);  // no registration: quick

  // The second scan's registration, and while it runs:
  const sensor_msgs::PointCloud2 second = cloudAt(0.5);
  spinFor(0.1);  // its tf first
  cloud_pub.publish(second);
  const double started = ros::WallTime::now().toSec();
  spinFor(0.3);
  ASSERT_EQ(out.statusAt(second.header.stamp), nullptr)
      << "the registration ended within 0.3 s: slow_registration.test's settings no longer "
         "make it slow, and this test would show nothing";
  // ... a service answers (a refused ~set_pose: it leaves the chain as it is),
  SetPose refused;
  refused.request.pose.header.frame_id = "not_the_map";
  refused.request.pose.pose.pose.orientation.w = 1.0;
  const double called = ros::WallTime::now().toSec();
  ASSERT_TRUE(ros::service::call(kNs + "set_pose", refused));
  const double answered = ros::WallTime::now().toSec();
  EXPECT_FALSE(refused.response.success);
  EXPECT_LT(answered - called, 0.1) << "~set_pose took " << answered - called << " s";
  // ... two more clouds arrive: the first is dropped when the second takes its place.
  const sensor_msgs::PointCloud2 third = cloudAt(0.5);
  spinFor(0.1);
  cloud_pub.publish(third);
  spinFor(0.1);
  const sensor_msgs::PointCloud2 fourth = cloudAt(0.5);
  spinFor(0.1);
  cloud_pub.publish(fourth);
  ASSERT_TRUE(waitFor([&] { return out.statusAt(second.header.stamp) != nullptr; }, 300.0));
  const double ended = ros::WallTime::now().toSec();
  ASSERT_GT(ended - started, 2.0) << "the registration took " << ended - started
                                  << " s: too short to see diagnostics and tf go on";
  EXPECT_EQ(out.statusAt(second.header.stamp)->reason, Status::ACCEPTED);
  ASSERT_TRUE(waitFor([&] { return out.statusAt(fourth.header.stamp) != nullptr; }, 300.0));
  EXPECT_EQ(out.statusAt(third.header.stamp), nullptr) << "the dropped cloud was registered";
  EXPECT_EQ(out.statusAt(fourth.header.stamp)->dropped_scans, 1u);

  // Diagnostics (every 1 s) and map -> odom (every 1 / tf_rate s) went on during it.
  auto largestGap = [&](const std::vector<double>& at) {
    double last = started, gap = 0.0;
    for (const double t : at) {
      if (t < started || t > ended) continue;
      gap = std::max(gap, t - last);
      last = t;
    }
    return std::max(gap, ended - last);
  };
  EXPECT_LT(largestGap(diagnostics_at), 1.6) << "diagnostics stopped during the registration";
  EXPECT_LT(largestGap(map_odom_at), 0.5) << "map -> odom stopped during the registration (tf_rate "
                                          << tf_rate << " Hz)";
  std::printf("[slow] registration %.2f s; ~set_pose answered in %.3f s; largest gaps: "
              "diagnostics %.2f s, map -> odom %.3f s\n",
              ended - started, answered - called, largestGap(diagnostics_at),
              largestGap(map_odom_at));
}

/// The matcher on simulated time (test/ros/sim_time.test): the test publishes /clock.
class ScanMatcherSimTime : public ScanMatcherRos {};

// Under simulated time map -> odom is sent after every scan and by a timer, each stamped
// now + transform_tolerance: within one step of the clock both would carry the same stamp,
// which tf listeners warn about (TF_REPEATED_DATA). A stamp is never sent twice.
TEST_F(ScanMatcherSimTime, MapOdomNeverRepeatsAStamp) {
  ros::Publisher clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 1, true);
  std::vector<ros::Time> stamps;  // of every map -> odom sent
  ros::Subscriber tf_sub = nh.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100, [&](const tf2_msgs::TFMessage::ConstPtr& m) {
        for (const auto& t : m->transforms) {
          if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
            stamps.push_back(t.header.stamp);
          }
        }
      });
  ros::Time now(1000.0);
  auto setClock = [&](const ros::Time& t) {
    rosgraph_msgs::Clock c;
    c.clock = now = t;
    clock_pub.publish(c);
    spinFor(0.3);
  };
  setClock(now);
  const sim::Scene scene = sim::Scene::generate(sim::SceneType::Urban, 3);
  std::mt19937_64 rng(41);
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.translation() = Eigen::Vector3d(0, 0, scene.groundHeight(0, 0) + 0.5);
  const PointArray pts = sweepInBase(scene, body, rng);
  auto sendAtNow = [&] {
    tf_pub.sendTransform(stampedTransform(body, "odom", "base_link", now));
    spinFor(0.1);
    return send(makeCloud(pts, "base_link", now));
  };
  EXPECT_EQ(sendAtNow().reason, Status::FIRST_SCAN);
  for (int k = 0; k < 8; ++k) {
    setClock(now + ros::Duration(0.25));  // the timer sends at this clock step...
    EXPECT_EQ(sendAtNow().reason, Status::ACCEPTED);  // ... and so does the scan
    spinFor(0.2);
  }
  ASSERT_GE(stamps.size(), 9u) << "map -> odom was not sent after each scan";
  std::vector<ros::Time> sorted = stamps;
  std::sort(sorted.begin(), sorted.end());
  const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
  EXPECT_EQ(repeated, sorted.end()) << "map -> odom sent twice at " << repeated->toSec() << " s ("
                                    << stamps.size() << " sent)";
}

// A bag replayed in a loop takes the clock back: the diagnostics go on at once (each tick is
// forced) instead of staying silent until the clock is back where it was.
TEST_F(ScanMatcherSimTime, DiagnosticsGoOnAfterTheClockJumpsBack) {
  ros::Publisher clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 1, true);
  std::vector<ros::Time> published;  // clock stamps of the matcher's diagnostics
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status) {
          if (s.name.find("scan_matcher") != std::string::npos) published.push_back(m->header.stamp);
        }
      });
  auto runClock = [&](double from, double seconds) {
    for (double t = from; t <= from + seconds + 1e-9; t += 0.25) {
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(t);
      clock_pub.publish(c);
      spinFor(0.1);
    }
  };
  runClock(2000.0, 4.0);
  const std::size_t before = published.size();
  ASSERT_GE(before, 2u) << "no diagnostics on simulated time";
  runClock(1500.0, 4.0);  // the loop: 500 s back
  std::size_t after = 0;
  for (std::size_t i = before; i < published.size(); ++i) after += published[i].toSec() < 1600.0;
  EXPECT_GE(after, 2u) << "diagnostics silent for 4 s of simulated time after the clock went back";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_scan_matcher");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
