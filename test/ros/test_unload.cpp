// A nodelet that outlives its unload (test/ros/unload.test). When a manager unloads a nodelet
// while one of the nodelet's callbacks runs on a manager thread, that thread holds the last
// reference and destroys the nodelet after the manager has let go of the nodelet's callback
// queues. Here the test holds that reference itself, so the order is certain: load into a
// nodelet::Loader (the manager's own class, with its worker threads), let the timers on both
// queues fire, unload, then drop the last reference. Destroying a handle on a freed queue
// crashes this program (SIGSEGV: a use of freed memory, caught by ASan in scripts/sanitize.sh).
#include <gtest/gtest.h>

#include <boost/make_shared.hpp>
#include <nodelet/loader.h>
#include <ros/ros.h>

#include "cube_scan_matcher/ros/scan_matcher_nodelet.h"
#include "cube_scan_matcher/ros/sweep_assembler_nodelet.h"

using namespace cube_scan_matcher;

namespace {

/// Loads `type` as `name` 20 times, each time into a new nodelet::Loader (the manager's own
/// class, with its worker threads): lets its callbacks run for 50 ms, unloads it, and then
/// drops the last reference to the nodelet, which the test now holds alone (as a manager
/// thread finishing a callback would): its destructor releases every handle after the
/// manager let go of its queues. The loader stays until then: in a manager process it
/// outlives every nodelet, and its queue manager is what the nodelet's queues report new
/// callbacks to.
void unloadTwentyTimes(const std::string& name, const std::string& type) {
  for (int i = 0; i < 20; ++i) {
    boost::shared_ptr<nodelet::Nodelet> kept;
    nodelet::Loader loader([&kept](const std::string& t) -> boost::shared_ptr<nodelet::Nodelet> {
      if (t == "ScanMatcherNodelet") kept = boost::make_shared<ScanMatcherNodelet>();
      if (t == "SweepAssemblerNodelet") kept = boost::make_shared<SweepAssemblerNodelet>();
      return kept;
    });
    EXPECT_TRUE(loader.load(name, type, {}, {}));
    ASSERT_TRUE(kept);
    ros::WallDuration(0.05).sleep();
    EXPECT_TRUE(loader.unload(name));
    EXPECT_EQ(loader.listLoadedNodelets().size(), 0u);
    // A manager thread finishing a callback may still hold a reference for a moment.
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(2.0);
    while (kept.use_count() > 1 && ros::WallTime::now() < deadline) ros::WallDuration(0.001).sleep();
    EXPECT_EQ(kept.use_count(), 1);
    kept.reset();
  }
}

}  // namespace

TEST(Unload, ScanMatcherOutlivingItsUnloadIsDestroyedSafely) {
  // map -> odom at 100 Hz: a timer on the multi-threaded queue beside the single-threaded
  // queue's diagnostics timer, subscriber, services and dynamic_reconfigure server.
  ros::param::set("/unload_test/scan_matcher/role", std::string("map_odom"));
  ros::param::set("/unload_test/scan_matcher/tf_rate", 100.0);
  unloadTwentyTimes("/unload_test/scan_matcher", "ScanMatcherNodelet");
  EXPECT_TRUE(ros::ok());
}

TEST(Unload, SweepAssemblerOutlivingItsUnloadIsDestroyedSafely) {
  unloadTwentyTimes("/unload_test/sweep_assembler", "SweepAssemblerNodelet");
  EXPECT_TRUE(ros::ok());
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_unload");
  ros::NodeHandle nh;  // keeps the node up between the loaders
  return RUN_ALL_TESTS();
}
