// rostest for SweepAssemblerNodelet, run twice: loaded into a nodelet manager
// (sweep_assembler.test) and as sweep_assembler_node (sweep_assembler_node.test).
//
// The test is the robot: it publishes tf (odom -> base_link moving at 1 m/s along x while
// turning at 10 deg/s, base_link -> laser_mount static, laser_mount -> laser tilting about x
// triangularly between -30 and +30 deg at 40 deg/s) and LaserScan lines at 50 Hz whose every
// beam hits the ground z = 0 of odom: each range is computed from the pose at the beam's own
// time. From each cloud's `time` field every point is traced back to its line and beam, and
// checked against that beam's exact point (1 mm): a projection with one pose per line would be
// 10 mm off (1 m/s over the 10 ms of a line), so this proves per-beam tf.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "cube_scan_matcher/ros/read_param.h"
#include "cube_scan_matcher/ros/sweep_assembler_nodelet.h"
#include "cube_scan_matcher/ros/transforms.h"
#include "ros_test_helpers.h"

using namespace cube_scan_matcher;
using cube_scan_matcher::test::waitFor;

namespace {

constexpr double kDeg = M_PI / 180.0;
// The scanner: 161 beams from -170 to -10 deg in the laser's xy plane, 2^-14 s apart (exact
// in float, so every time below is exact in nanoseconds), one line every 20 ms.
constexpr int kBeams = 161;
constexpr double kAngleMin = -170.0 * kDeg, kAngleInc = 1.0 * kDeg;
constexpr double kTimeInc = 1.0 / 16384.0;
constexpr double kLinePeriod = 0.02;
constexpr double kLineSpan = (kBeams - 1) * kTimeInc;  // 9.765625 ms
constexpr float kRangeMin = 0.1f, kRangeMax = 4.0f;
// The tilt: from -30 deg at s = 0 to +30 at 1.5 s and back: a turning point every 75 lines.
constexpr double kAmp = 30.0 * kDeg, kHalf = 1.5;
constexpr int kLinesPerHalf = 75;
constexpr double kSpeed = 1.0, kYawRate = 10.0 * kDeg;
constexpr int kLines = 4 * kLinesPerHalf + 11;  // four turning points, then 10 lines
constexpr int kEmptyLine = 40;                   // every beam NaN: counts, adds no point

double tilt(double s) {
  const double phase = std::fmod(s, 2.0 * kHalf) / kHalf;
  return phase < 1.0 ? -kAmp + 2.0 * kAmp * phase : kAmp - 2.0 * kAmp * (phase - 1.0);
}
Eigen::Isometry3d odomBase(double s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(kSpeed * s, 0.0, 0.0);
  T.linear() = Eigen::AngleAxisd(kYawRate * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}
/// laser_mount in base_link: 1 m up, its x forward and its xy plane vertical, so the scan plane
/// is vertical at tilt 0 and the tilt about x rolls it sideways.
Eigen::Isometry3d baseMount() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.2, 0.0, 1.0);
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return T;
}
Eigen::Isometry3d mountLaser(double s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(tilt(s), Eigen::Vector3d::UnitX()).toRotationMatrix();
  return T;
}
Eigen::Isometry3d odomLaser(double s) { return odomBase(s) * baseMount() * mountLaser(s); }

double lineStart(int k) { return k * kLinePeriod; }
double beamAngle(int i) { return double(float(kAngleMin)) + i * double(float(kAngleInc)); }

/// Range of beam i of line k as published (float): the ground hit from the pose at the beam's
/// time; NaN for dropouts (every 17th beam) and the empty line, inf when it misses.
float publishedRange(int k, int i) {
  if (k == kEmptyLine || i % 17 == 5) return std::numeric_limits<float>::quiet_NaN();
  const Eigen::Isometry3d T = odomLaser(lineStart(k) + i * kTimeInc);
  const Eigen::Vector3d d = T.linear() * Eigen::Vector3d(std::cos(beamAngle(i)), std::sin(beamAngle(i)), 0);
  if (d.z() > -1e-3) return std::numeric_limits<float>::infinity();
  return float(-T.translation().z() / d.z());
}
bool valid(int k, int i) {
  const float r = publishedRange(k, i);
  return std::isfinite(r) && r >= kRangeMin && r < kRangeMax;
}
Eigen::Vector3d truePoint(int k, int i) {
  const Eigen::Isometry3d T = odomLaser(lineStart(k) + i * kTimeInc);
  return T * (double(publishedRange(k, i)) *
              Eigen::Vector3d(std::cos(beamAngle(i)), std::sin(beamAngle(i)), 0));
}

std::string diagValue(const diagnostic_msgs::DiagnosticStatus& s, const std::string& key) {
  for (const auto& kv : s.values) {
    if (kv.key == key) return kv.value;
  }
  return "";
}

/// How one run of kLines lines is published.
struct Schedule {
  double tf_delay = 0.0;                       ///< [s] tf sent this long after its stamp
  std::function<bool(double)> tf_missing;      ///< no tf sample at s (seconds from T0)
  int swap_first = -1;  ///< this line is sent 0.1 s after the next one (after 5 newer lines)
  double stamp_offset = 0.0;                   ///< [s] stamps this much before the wall clock
};

class SweepAssemblerRos : public ::testing::Test {
 protected:
  ros::NodeHandle nh;
  ros::Publisher scan_pub = nh.advertise<sensor_msgs::LaserScan>("/test_scan", 400);
  ros::Publisher tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf", 400);
  tf2_ros::StaticTransformBroadcaster static_pub;
  std::vector<sensor_msgs::PointCloud2> clouds;
  ros::Subscriber cloud_sub, diag_sub;
  diagnostic_msgs::DiagnosticStatus status;  // the assembler's latest
  ros::Time t0;
  std::uint32_t seq = 0;

  void SetUp() override {
    cloud_sub = nh.subscribe<sensor_msgs::PointCloud2>(
        "/test_cloud", 50, [this](const sensor_msgs::PointCloud2::ConstPtr& m) { clouds.push_back(*m); });
    diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 50, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
          for (const auto& s : m->status) {
            if (s.name.find("sweep_assembler: ") != std::string::npos) status = s;
          }
        });
    ASSERT_TRUE(waitFor([&] { return scan_pub.getNumSubscribers() > 0 && cloud_sub.getNumPublishers() > 0; }, 30.0))
        << "the assembler did not connect to /test_scan and /test_cloud";
    ASSERT_TRUE(waitFor([&] { return !status.name.empty(); }, 10.0)) << "no diagnostics";
    static_pub.sendTransform(stampedTransform(baseMount(), "base_link", "laser_mount", ros::Time(0)));
    waitFor([] { return false; }, 0.5);
  }

  std::uint64_t counter(const std::string& key) { return std::stoull(diagValue(status, key)); }

  /// Waits for diagnostics that have seen `received` lines; returns the counter `key`.
  std::uint64_t counterAfter(std::uint64_t received, const std::string& key) {
    EXPECT_TRUE(waitFor([&] { return counter("lines received") >= received; }, 10.0))
        << "diagnostics never reached " << received << " lines received";
    return counter(key);
  }

  sensor_msgs::LaserScan line(int k) {
    sensor_msgs::LaserScan scan;
    scan.header.stamp = t0 + ros::Duration(lineStart(k));
    scan.header.frame_id = "laser";
    scan.header.seq = ++seq;
    scan.angle_min = float(kAngleMin);
    scan.angle_increment = float(kAngleInc);
    scan.angle_max = float(kAngleMin + (kBeams - 1) * kAngleInc);
    scan.time_increment = float(kTimeInc);
    scan.scan_time = float(kLinePeriod);
    scan.range_min = kRangeMin;
    scan.range_max = kRangeMax;
    for (int i = 0; i < kBeams; ++i) {
      scan.ranges.push_back(publishedRange(k, i));
      scan.intensities.push_back(float(i));
    }
    return scan;
  }

  void sendTf(double s) {
    const ros::Time stamp = t0 + ros::Duration(s);
    tf2_msgs::TFMessage m;
    m.transforms.push_back(stampedTransform(odomBase(s), "odom", "base_link", stamp));
    m.transforms.push_back(stampedTransform(mountLaser(s), "laser_mount", "laser", stamp));
    tf_pub.publish(m);
  }

  /// Publishes the kLines lines in real time (a line when its last beam is measured) and tf
  /// samples at each line's first and last beam, then waits for the clouds.
  void publish(const Schedule& run) {
    t0 = ros::Time::now() + ros::Duration(0.3 - run.stamp_offset);
    clouds.clear();
    std::vector<std::pair<double, double>> tf_due;  // (due, sample) in s from t0
    for (int k = 0; k < kLines; ++k) {
      for (double s : {lineStart(k), lineStart(k) + kLineSpan}) {
        if (!run.tf_missing || !run.tf_missing(s)) tf_due.emplace_back(s + run.tf_delay, s);
      }
    }
    std::vector<std::pair<double, int>> line_due;
    for (int k = 0; k < kLines; ++k) line_due.emplace_back(lineStart(k) + kLineSpan + 0.001, k);
    if (run.swap_first >= 0) {
      line_due[std::size_t(run.swap_first)].first = line_due[std::size_t(run.swap_first) + 1].first + 0.1;
    }
    std::stable_sort(line_due.begin(), line_due.end());
    std::size_t next_tf = 0, next_line = 0;
    while (ros::ok() && (next_tf < tf_due.size() || next_line < line_due.size())) {
      const double now = (ros::Time::now() - t0).toSec() - run.stamp_offset;
      while (next_tf < tf_due.size() && tf_due[next_tf].first <= now) sendTf(tf_due[next_tf++].second);
      while (next_line < line_due.size() && line_due[next_line].first <= now) {
        scan_pub.publish(line(line_due[next_line++].second));
      }
      ros::spinOnce();
      ros::WallDuration(0.001).sleep();
    }
  }

  /// Checks every cloud stamped after t0: layout, frame, stamps, each point against its beam.
  /// Returns, per cloud, its first and last line; `exact(first, last)` says which clouds must
  /// be exact (all, but those touched by a tf gap): each point within 1 mm of its beam's and
  /// every valid beam of the cloud's lines there, but those of the `missing` lines.
  std::vector<std::pair<int, int>> check(const std::function<bool(int, int)>& exact,
                                         std::set<int>* lines_seen, const std::set<int>& missing = {}) {
    std::vector<std::pair<int, int>> spans;
    for (const auto& c : clouds) {
      // A sweep left over from an earlier test (later stamps after a jump back in time).
      if (c.header.stamp < t0 || c.header.stamp > t0 + ros::Duration(kLines * kLinePeriod)) continue;
      EXPECT_EQ(c.header.frame_id, "odom");
      EXPECT_EQ(c.height, 1u);
      EXPECT_TRUE(c.is_dense);
      std::vector<std::string> names;
      for (const auto& f : c.fields) {
        names.push_back(f.name);
        EXPECT_EQ(f.datatype, sensor_msgs::PointField::FLOAT32) << f.name;
      }
      EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "intensity", "time"}));
      if (c.width == 0) continue;
      sensor_msgs::PointCloud2ConstIterator<float> x(c, "x"), y(c, "y"), z(c, "z"),
          in(c, "intensity"), t(c, "time");
      std::set<std::pair<int, int>> beams;
      std::map<int, int> per_line;
      float last_time = -1e9f;
      double worst = 0.0, worst_plane = 0.0;
      for (std::uint32_t n = 0; n < c.width; ++n, ++x, ++y, ++z, ++in, ++t) {
        EXPECT_GE(*t, last_time) << "time goes backwards at point " << n;
        EXPECT_LE(*t, 1e-6f) << "time after the header stamp";
        last_time = *t;
        const double s = (c.header.stamp - t0).toSec() + double(*t);
        const int k = int(std::floor((s + 0.005) / kLinePeriod));
        const int i = int(std::lround((s - lineStart(k)) / kTimeInc));
        if (!(k >= 0 && k < kLines && i >= 0 && i < kBeams)) {
          ADD_FAILURE() << "time " << *t << " is no beam's";
          continue;
        }
        EXPECT_NEAR(s, lineStart(k) + i * kTimeInc, 2e-6) << "line " << k << " beam " << i;
        EXPECT_EQ(*in, float(i)) << "intensity of line " << k << " beam " << i;
        EXPECT_TRUE(valid(k, i)) << "line " << k << " beam " << i << " should have been dropped";
        EXPECT_TRUE(beams.insert({k, i}).second) << "line " << k << " beam " << i << " twice";
        ++per_line[k];
        if (valid(k, i)) {
          worst = std::max(worst, (Eigen::Vector3d(*x, *y, *z) - truePoint(k, i)).norm());
          worst_plane = std::max(worst_plane, std::abs(double(*z)));
        }
      }
      const int first = per_line.begin()->first, last = per_line.rbegin()->first;
      spans.emplace_back(first, last);
      for (const auto& [k, count] : per_line) {
        if (lines_seen) {
          EXPECT_TRUE(lines_seen->insert(k).second) << "line " << k << " in two clouds";
        }
      }
      // The header stamp: the last beam of the sweep's last line (kEmptyLine is never last).
      EXPECT_NEAR((c.header.stamp - t0).toSec(), lineStart(last) + kLineSpan, 1e-6);
      if (exact(first, last)) {
        EXPECT_LT(worst, 1e-3) << "cloud of lines " << first << "-" << last;
        EXPECT_LT(worst_plane, 1e-3) << "cloud of lines " << first << "-" << last;
        int expected = 0;  // every valid beam of every line of the sweep
        for (int k = first; k <= last; ++k) {
          if (missing.count(k)) continue;
          for (int i = 0; i < kBeams; ++i) expected += valid(k, i) ? 1 : 0;
        }
        EXPECT_EQ(int(c.width), expected) << "cloud of lines " << first << "-" << last;
      }
    }
    return spans;
  }
};

/// The sweeps between the turning points (line 75 j is the extreme, +-30 deg).
const std::vector<std::pair<int, int>> kExpectedSpans = {{0, 75}, {76, 150}, {151, 225}, {226, 300}};

TEST_F(SweepAssemblerRos, OneExactCloudPerHalfPeriodAndALateLineIsDropped) {
  const std::uint64_t received0 = counter("lines received"), late0 = counter("lines late");
  const std::uint64_t dropped0 = counter("lines dropped without tf");
  Schedule run;
  run.swap_first = 100;  // line 100 is sent after 101-105 were used: it is late
  publish(run);
  ASSERT_TRUE(waitFor([&] { return clouds.size() >= 4; }, 5.0)) << clouds.size() << " clouds";
  std::set<int> seen;
  const auto spans = check([](int, int) { return true; }, &seen, {100});
  // Line 100 is missing from its cloud: the span is still 76-150 but one line short.
  EXPECT_EQ(spans, kExpectedSpans);
  EXPECT_EQ(seen.count(100), 0u);
  EXPECT_EQ(seen.count(kEmptyLine), 0u);
  EXPECT_EQ(int(seen.size()), 301 - 2);  // every line up to the last turning point but two
  EXPECT_EQ(counterAfter(received0 + kLines, "lines late") - late0, 1u);
  EXPECT_EQ(counter("lines dropped without tf") - dropped0, 0u);
}

/// The nodelet test only (test/ros/sweep_assembler.test): a second assembler on the same lines
/// with the wrong tilt axis.
class SweepAssemblerWrongAxis : public SweepAssemblerRos {};

// An assembler given the wrong tilt axis (y, while the laser tilts about x) sees no tilt
// motion: its stall WARN names tilt_axis and tilt_reference_frame, the settings to check.
TEST_F(SweepAssemblerWrongAxis, StallsAndTheWarningNamesTheAxis) {
  std::string wrong_axis_warning;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 50, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status) {
          if (s.name.find("sweep_assembler_wrong_axis: ") != std::string::npos &&
              s.level == diagnostic_msgs::DiagnosticStatus::WARN) {
            wrong_axis_warning = s.message;
          }
        }
      });
  publish(Schedule{});
  ASSERT_TRUE(waitFor([&] { return !wrong_axis_warning.empty(); }, 10.0))
      << "the assembler with tilt_axis y never warned";
  EXPECT_NE(wrong_axis_warning.find("tilt stalled"), std::string::npos) << wrong_axis_warning;
  EXPECT_NE(wrong_axis_warning.find("tilt_axis y"), std::string::npos) << wrong_axis_warning;
  EXPECT_NE(wrong_axis_warning.find("'laser_mount' (tilt_reference_frame)"), std::string::npos)
      << wrong_axis_warning;
  EXPECT_GE(clouds.size(), 4u) << "the assembler with the right axis assembles the same lines";
}

TEST_F(SweepAssemblerRos, TfLateBy200msLosesNoLineAndOutOfOrderLinesAreSorted) {
  const std::uint64_t received0 = counter("lines received"), late0 = counter("lines late");
  const std::uint64_t dropped0 = counter("lines dropped without tf");
  Schedule run;
  run.tf_delay = 0.2;    // < tf_timeout 0.5: every line waits for its tf
  run.swap_first = 100;  // 101-105 still wait for tf when 100 comes: it is put back in order
  publish(run);
  ASSERT_TRUE(waitFor([&] { return clouds.size() >= 4; }, 5.0)) << clouds.size() << " clouds";
  std::set<int> seen;
  EXPECT_EQ(check([](int, int) { return true; }, &seen), kExpectedSpans);
  EXPECT_EQ(int(seen.size()), 301 - 1);  // all but the empty line
  EXPECT_EQ(counterAfter(received0 + kLines, "lines dropped without tf") - dropped0, 0u);
  EXPECT_EQ(counter("lines late") - late0, 0u);
}

TEST_F(SweepAssemblerRos, ATfGapLongerThanTfTimeoutDropsLinesAndAssemblyGoesOn) {
  const std::uint64_t received0 = counter("lines received");
  const std::uint64_t dropped0 = counter("lines dropped without tf");
  const std::uint64_t discarded0 = counter("lines in discarded sweeps");
  Schedule run;
  const double gap_start = 2.0, gap_end = 3.6;  // 1.6 s without tf (tf_timeout 0.5)
  run.tf_missing = [=](double s) { return s > gap_start && s < gap_end; };
  publish(run);
  ASSERT_TRUE(waitFor([&] {
    for (const auto& c : clouds) {
      if (c.header.stamp > t0 + ros::Duration(4.0)) return true;
    }
    return false;
  }, 5.0)) << "no cloud after the tf gap";
  const std::uint64_t dropped = counterAfter(received0 + kLines, "lines dropped without tf") - dropped0;
  // Lines waiting when tf came back (the last tf_timeout of the gap) are placed with tf
  // interpolated across the gap; the older ones were dropped.
  EXPECT_GE(dropped, std::uint64_t((gap_end - gap_start - 0.5 - 0.15) / kLinePeriod));
  EXPECT_LE(dropped, std::uint64_t((gap_end - gap_start) / kLinePeriod) + 1);
  std::set<int> seen;
  const int gap_first_line = int(gap_start / kLinePeriod);
  const int gap_last_line = int(gap_end / kLinePeriod) + 1;
  const auto spans = check([&](int first, int last) {
    return last < gap_first_line || first > gap_last_line;
  }, &seen);
  ASSERT_FALSE(spans.empty());
  EXPECT_EQ(spans.front(), kExpectedSpans.front());
  EXPECT_EQ(spans.back(), kExpectedSpans.back());
  // No line lost silently: each line up to the last turning point is in a cloud, or counted as
  // dropped or in a discarded sweep (but the empty one).
  const std::uint64_t discarded = counter("lines in discarded sweeps") - discarded0;
  EXPECT_EQ(seen.size() + dropped + discarded, std::size_t(301 - 1));
}

TEST_F(SweepAssemblerRos, TimeGoingBackwardsResetsOnceAndAssemblyGoesOn) {
  const std::uint64_t received0 = counter("lines received"), resets0 = counter("time resets");
  const std::uint64_t dropped0 = counter("lines dropped without tf");
  Schedule run;
  run.stamp_offset = 20.0;  // a bag loop: stamps 20 s before the previous test's
  publish(run);
  ASSERT_TRUE(waitFor([&] {
    for (const auto& c : clouds) {
      if (c.header.stamp > t0 + ros::Duration(5.0) && c.header.stamp < t0 + ros::Duration(7.0)) return true;
    }
    return false;
  }, 5.0)) << "no cloud after the jump back";
  EXPECT_EQ(counterAfter(received0 + kLines, "time resets") - resets0, 1u);
  // The tf buffer is cleared when the first line of the new time line arrives: the tf sent
  // just before it is lost with the old, so its first line(s) may be dropped (counted).
  const std::uint64_t dropped = counter("lines dropped without tf") - dropped0;
  EXPECT_LE(dropped, 2u);
  std::set<int> seen;
  const auto spans = check([](int, int) { return true; }, &seen);
  ASSERT_EQ(spans.size(), kExpectedSpans.size());
  using Spans = std::vector<std::pair<int, int>>;
  EXPECT_EQ(Spans(spans.begin() + 1, spans.end()), Spans(kExpectedSpans.begin() + 1, kExpectedSpans.end()));
  EXPECT_EQ(spans.front().second, kExpectedSpans.front().second);
  EXPECT_EQ(seen.size() + dropped, std::size_t(301 - 1));
}

// config/sweep_assembler.yaml: loads (with a tilt frame: the YAML alone has neither a tilt
// frame nor a duration, and is refused naming sweep_duration), equals the code's defaults,
// and every parameter in it is read and validated by the nodelet and has a docs/parameters.md row with
// the same default.
TEST(SweepAssemblerYaml, HoldsTheDefaultsAndEveryParameterIsReadAndDocumented) {
  const std::string ns = "/yaml_check";
  ros::NodeHandle pnh(ns);
  try {
    loadAssemblerParams(pnh);
    ADD_FAILURE() << "the YAML alone was accepted";
  } catch (const ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("sweep_duration"), std::string::npos) << e.what();
  }
  pnh.setParam("tilt_reference_frame", "laser_mount");
  AssemblerParams p;
  ASSERT_NO_THROW(p = loadAssemblerParams(pnh));
  const AssemblerParams d;
  EXPECT_EQ(p.fixed_frame, d.fixed_frame);
  EXPECT_EQ(p.tilt_axis, d.tilt_axis);
  EXPECT_DOUBLE_EQ(p.cutter.turn_hysteresis, d.cutter.turn_hysteresis);
  EXPECT_DOUBLE_EQ(p.cutter.sweep_duration, d.cutter.sweep_duration);
  EXPECT_DOUBLE_EQ(p.cutter.stall_timeout, d.cutter.stall_timeout);
  EXPECT_DOUBLE_EQ(p.cutter.max_line_gap, d.cutter.max_line_gap);
  EXPECT_EQ(p.cutter.min_lines, d.cutter.min_lines);
  EXPECT_EQ(p.cutter.max_lines, d.cutter.max_lines);
  EXPECT_DOUBLE_EQ(p.tf_timeout, d.tf_timeout);
  EXPECT_DOUBLE_EQ(p.range_min, d.range_min);
  EXPECT_DOUBLE_EQ(p.range_max, d.range_max);
  EXPECT_EQ(p.queue_size, d.queue_size);

  // Every YAML key: a value of the wrong type must be refused naming it.
  std::ifstream yaml(CSM_SOURCE_DIR "/config/sweep_assembler.yaml");
  ASSERT_TRUE(yaml.good());
  std::map<std::string, std::string> defaults;
  for (std::string l; std::getline(yaml, l);) {
    if (l.empty() || l[0] == '#') continue;
    const std::size_t colon = l.find(':'), hash = l.find('#');
    ASSERT_NE(colon, std::string::npos) << l;
    ASSERT_NE(hash, std::string::npos) << "undocumented: " << l;
    std::string value = l.substr(colon + 1, hash - colon - 1);
    value.erase(value.find_last_not_of(' ') + 1);
    value.erase(0, value.find_first_not_of(' '));
    defaults[l.substr(0, colon)] = value;
  }
  EXPECT_EQ(defaults.size(), 13u);
  for (const auto& [name, value] : defaults) {
    ros::NodeHandle scratch("/yaml_check_" + name);
    scratch.setParam("tilt_reference_frame", "laser_mount");
    XmlRpc::XmlRpcValue wrong;
    wrong[0] = 1;
    wrong[1] = 2;  // a list: no parameter takes one
    scratch.setParam(name, wrong);
    try {
      loadAssemblerParams(scratch);
      ADD_FAILURE() << "~" << name << " set to a list was accepted: is it read?";
    } catch (const ParamError& e) {
      EXPECT_NE(std::string(e.what()).find("~" + name), std::string::npos) << e.what();
    }
  }
  // docs/parameters.md: "| name | unit | default | range | meaning |" rows in the
  // "SweepAssemblerNodelet" section.
  std::ifstream doc_file(CSM_SOURCE_DIR "/docs/parameters.md");
  ASSERT_TRUE(doc_file.good()) << "docs/parameters.md not found";
  bool in_section = false;
  std::map<std::string, std::string> documented;
  for (std::string l; std::getline(doc_file, l);) {
    if (l.rfind("## ", 0) == 0) in_section = l == "## SweepAssemblerNodelet";
    if (!in_section || l.rfind("| ", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream ss(l);
    for (std::string cell; std::getline(ss, cell, '|');) {
      cell.erase(cell.find_last_not_of(' ') + 1);
      cell.erase(0, cell.find_first_not_of(' '));
      cells.push_back(cell);
    }
    if (cells.size() >= 6 && defaults.count(cells[1])) documented[cells[1]] = cells[3];
  }
  for (const auto& [name, value] : defaults) {
    ASSERT_EQ(documented.count(name), 1u) << "docs/parameters.md has no row for " << name;
    const std::string& doc = documented[name];
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    if (end != value.c_str() && *end == '\0') {
      EXPECT_DOUBLE_EQ(std::stod(doc), number) << "docs/parameters.md default of " << name;
    } else {
      EXPECT_EQ(doc, value == "\"\"" ? "\"\"" : value) << "docs/parameters.md default of " << name;
    }
  }
}

// A second assembler in the same manager with tilt_axis: w (test/ros/sweep_assembler.test):
// it refuses to start naming the parameter, at ERROR in the diagnostics, and the manager (and
// the first assembler in it) lives on.
TEST(SweepAssemblerBadParam, RefusesToStartAndNamesTheParameter) {
  ros::NodeHandle nh;
  std::string bad_name;
  if (!ros::param::get("~bad_param_nodelet", bad_name)) {
    GTEST_SKIP() << "no bad-parameter nodelet in this launch";
  }
  bool found = false;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status) {
          if (s.name.find(bad_name + ": ") != std::string::npos &&
              s.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
              s.message.find("~tilt_axis") != std::string::npos) {
            found = true;
          }
        }
      });
  EXPECT_TRUE(waitFor([&] { return found; }, 20.0)) << "no ERROR diagnostic naming ~tilt_axis";
  std::string manager;
  ros::param::get("~manager_node", manager);
  ros::V_string nodes;
  ros::master::getNodes(nodes);
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), manager), nodes.end()) << manager << " went down";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_sweep_assembler");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
