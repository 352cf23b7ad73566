// rostest (odometry_lost.test): the odometry tf stops after the first sweeps while the
// simulator drives on through a tunnel. The matcher carries the chain without odometry
// (constant velocity, most scans rejected, forced on after max_consecutive_rejections); no NaN
// or infinite value may reach ~pose, ~odometry or map -> odom, and the nodelet keeps answering.
#include <gtest/gtest.h>

#include <cmath>

#include <geometry_msgs/Pose.h>
#include <tf2_ros/transform_listener.h>

#include "ros_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

namespace {

bool finitePose(const geometry_msgs::Pose& p) {
  const auto& q = p.orientation;
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(n) && std::abs(n - 1.0) < 1e-6;
}

template <typename Array>
bool allFinite(const Array& a) {
  for (double v : a) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

TEST(OdometryLost, NoNonFiniteValueIsPublished) {
  ros::NodeHandle nh, pnh("~");
  const int sweeps = pnh.param("sweeps", 150), with_odometry = pnh.param("odometry_sweeps", 3);
  Outputs out(nh, "/scan_matcher/");
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);
  // Every sweep gets a status, or is counted as dropped (queue_size 1: the newest wins).
  const auto all_seen = [&] {
    return !out.status.empty() && int(out.status.size() + out.status.back().dropped_scans) >= sweeps;
  };
  ASSERT_TRUE(waitFor(all_seen, 280.0)) << out.status.size() << " statuses of " << sweeps << " sweeps";
  spinFor(0.5);

  int without_odometry = 0, forced = 0;
  for (std::size_t i = 0; i < out.status.size(); ++i) {
    const Status& s = out.status[i];
    if (s.tf_failed) ++without_odometry;
    if (int(s.consecutive_rejections) >= 5) ++forced;
    EXPECT_NE(s.reason, Status::NON_FINITE) << "status " << i << ": " << s.message;
  }
  std::printf("%zu statuses, %d without odometry, %d with >= 5 rejections in a row\n",
              out.status.size(), without_odometry, forced);
  // The run exercised what it is for: most of the drive without odometry.
  EXPECT_GE(without_odometry, (sweeps - with_odometry) / 2);
  ASSERT_FALSE(out.pose.empty());
  for (std::size_t i = 0; i < out.pose.size(); ++i) {
    EXPECT_TRUE(finitePose(out.pose[i].pose.pose)) << "pose " << i;
    EXPECT_TRUE(allFinite(out.pose[i].pose.covariance)) << "pose covariance " << i;
  }
  for (std::size_t i = 0; i < out.odom.size(); ++i) {
    const auto& t = out.odom[i].twist.twist;
    EXPECT_TRUE(finitePose(out.odom[i].pose.pose)) << "odometry " << i;
    EXPECT_TRUE(std::isfinite(t.linear.x) && std::isfinite(t.linear.y) && std::isfinite(t.linear.z) &&
                std::isfinite(t.angular.x) && std::isfinite(t.angular.y) && std::isfinite(t.angular.z))
        << "odometry twist " << i;
  }
  // map -> odom as the matcher last sent it (it keeps re-sending it while the odometry is lost).
  geometry_msgs::TransformStamped map_odom;
  ASSERT_NO_THROW(map_odom = tf_buffer.lookupTransform("map", "odom", ros::Time(0)));
  const auto& r = map_odom.transform.rotation;
  const auto& v = map_odom.transform.translation;
  EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(r.w) &&
              std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.z));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_odometry_lost");
  return RUN_ALL_TESTS();
}
