// PointCloud2 reading without a ROS master: float32 and float64 x/y/z, organised clouds with
// NaN, and malformed messages that must give a clear CloudError instead of a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include <sensor_msgs/point_cloud2_iterator.h>

#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/ros/cloud_conversion.h"

using namespace cube_scan_matcher;

namespace {

sensor_msgs::PointCloud2 doubleCloud(std::size_t n) {
  sensor_msgs::PointCloud2 c;
  sensor_msgs::PointCloud2Modifier m(c);
  m.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT64, "y", 1,
                         sensor_msgs::PointField::FLOAT64, "intensity", 1,
                         sensor_msgs::PointField::FLOAT32, "z", 1,
                         sensor_msgs::PointField::FLOAT64);
  m.resize(n);
  // z sits at byte 20 of a 28-byte record: misaligned for a double, so the values are written
  // with memcpy (a PointCloud2Iterator<double> would bind a misaligned reference: UB).
  const auto offset = [&c](const std::string& name) {
    for (const auto& f : c.fields) {
      if (f.name == name) return std::size_t(f.offset);
    }
    throw std::logic_error("no field " + name);
  };
  const std::size_t ox = offset("x"), oy = offset("y"), oz = offset("z");
  for (std::size_t i = 0; i < n; ++i) {
    const double v[3] = {double(i), 2.0 * double(i), -1.0};
    std::uint8_t* record = c.data.data() + i * c.point_step;
    std::memcpy(record + ox, &v[0], sizeof(double));
    std::memcpy(record + oy, &v[1], sizeof(double));
    std::memcpy(record + oz, &v[2], sizeof(double));
  }
  return c;
}

}  // namespace

TEST(CloudConversion, RoundTripsFloat32AndAppliesTheTransform) {
  PointArray p;
  p.push_back(1, 2, 3);
  p.push_back(-4, 5, 0.5f);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(10, 0, 0);
  const sensor_msgs::PointCloud2 c = toCloud(p, Eigen::Isometry3d::Identity(), std_msgs::Header{});
  const PointArray q = fromCloud(c, T);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_FLOAT_EQ(q.x[0], 11.0f);
  EXPECT_FLOAT_EQ(q.y[1], 5.0f);
  EXPECT_FLOAT_EQ(q.z[1], 0.5f);
}

TEST(CloudConversion, AnEmptyCloudRoundTrips) {
  // toCloud used to build iterators on the empty data (UBSan: reference binding to null).
  const sensor_msgs::PointCloud2 c =
      toCloud(PointArray{}, Eigen::Isometry3d::Identity(), std_msgs::Header{});
  EXPECT_EQ(c.width * c.height, 0u);
  EXPECT_TRUE(c.data.empty());
  EXPECT_TRUE(fromCloud(c, Eigen::Isometry3d::Identity()).empty());
}

TEST(CloudConversion, ReadsFloat64WithOtherFieldsBetween) {
  const PointArray q = fromCloud(doubleCloud(5));
  ASSERT_EQ(q.size(), 5u);
  EXPECT_FLOAT_EQ(q.x[4], 4.0f);
  EXPECT_FLOAT_EQ(q.y[4], 8.0f);
  EXPECT_FLOAT_EQ(q.z[4], -1.0f);
}

TEST(CloudConversion, OrganisedNaNPointsAreKeptForTheFilterToDrop) {
  PointArray p;
  p.push_back(1, 1, 1);
  p.push_back(NAN, NAN, NAN);
  sensor_msgs::PointCloud2 c = toCloud(p, Eigen::Isometry3d::Identity(), std_msgs::Header{});
  const PointArray q = fromCloud(c);
  ASSERT_EQ(q.size(), 2u);
  FilterStats stats;
  EXPECT_EQ(filterPoints(q, RangeFilterSettings{}, &stats).size(), 1u);
  EXPECT_EQ(stats.non_finite, 1u);
}

TEST(CloudConversion, MalformedCloudsGiveAClearError) {
  sensor_msgs::PointCloud2 noxyz;
  sensor_msgs::PointCloud2Modifier(noxyz).setPointCloud2FieldsByString(1, "rgb");
  sensor_msgs::PointCloud2Modifier(noxyz).resize(3);
  try {
    fromCloud(noxyz);
    FAIL() << "no error";
  } catch (const CloudError& e) {
    EXPECT_NE(std::string(e.what()).find("no x/y/z"), std::string::npos) << e.what();
  }
  sensor_msgs::PointCloud2 truncated = doubleCloud(100);
  truncated.data.resize(truncated.data.size() / 2);
  EXPECT_THROW(fromCloud(truncated), CloudError);
  sensor_msgs::PointCloud2 ints = doubleCloud(3);
  for (auto& f : ints.fields) f.datatype = sensor_msgs::PointField::INT32;
  EXPECT_THROW(fromCloud(ints), CloudError);
  sensor_msgs::PointCloud2 empty = doubleCloud(0);
  EXPECT_TRUE(fromCloud(empty).empty());
}

TEST(CloudConversion, PointTimesAreReadBesideThePointsAndFilteredWithThem) {
  sensor_msgs::PointCloud2 c;
  sensor_msgs::PointCloud2Modifier m(c);
  m.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                         sensor_msgs::PointField::FLOAT32, "z", 1, sensor_msgs::PointField::FLOAT32,
                         "time", 1, sensor_msgs::PointField::FLOAT32);
  m.resize(4);
  sensor_msgs::PointCloud2Iterator<float> x(c, "x"), y(c, "y"), z(c, "z"), t(c, "time");
  const float nan = std::nanf("");
  const float xs[4] = {1, nan, 3, 4}, ts[4] = {-0.3f, -0.2f, nan, 0.0f};
  for (int i = 0; i < 4; ++i, ++x, ++y, ++z, ++t) *x = xs[i], *y = 0, *z = 0, *t = ts[i];
  const std::vector<float> times = readFloatField(c, "time");
  ASSERT_EQ(times.size(), 4u);
  EXPECT_FLOAT_EQ(times[0], -0.3f);
  EXPECT_TRUE(readFloatField(c, "t").empty());  // no such field: a rigid sweep
  // A point without a position or without a time is dropped with its time.
  std::vector<float> kept;
  FilterStats st;
  const PointArray pts = filterPoints(fromCloud(c), times, RangeFilterSettings{}, kept, &st);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(kept, (std::vector<float>{-0.3f, 0.0f}));
  EXPECT_FLOAT_EQ(pts.x[1], 4.0f);
  EXPECT_EQ(st.non_finite, 2u);
  // A time field of another type is named.
  c.fields[3].datatype = sensor_msgs::PointField::UINT32;
  try {
    readFloatField(c, "time");
    FAIL() << "no CloudError";
  } catch (const CloudError& e) {
    EXPECT_NE(std::string(e.what()).find("time"), std::string::npos) << e.what();
  }
}

// Drivers write intensity as uint8, uint16 or float32: each is read as float, and an
// unreadable one is reported without throwing (the scan stays usable).
TEST(CloudConversion, IntensityOfAnyScalarTypeIsReadAsFloat) {
  sensor_msgs::PointCloud2 c;
  sensor_msgs::PointCloud2Modifier m(c);
  m.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                         sensor_msgs::PointField::FLOAT32, "z", 1, sensor_msgs::PointField::FLOAT32,
                         "intensity", 1, sensor_msgs::PointField::UINT16);
  m.resize(3);
  sensor_msgs::PointCloud2Iterator<std::uint16_t> in(c, "intensity");
  const std::uint16_t values[3] = {0, 700, 65535};
  for (int i = 0; i < 3; ++i, ++in) *in = values[i];
  std::string problem;
  const auto intensity = readIntensity(c, problem);
  ASSERT_TRUE(intensity) << problem;
  EXPECT_EQ(*intensity, (std::vector<float>{0.0f, 700.0f, 65535.0f}));
  EXPECT_TRUE(problem.empty());

  c.fields[3].datatype = 42;  // no such datatype
  EXPECT_FALSE(readIntensity(c, problem));
  EXPECT_NE(problem.find("intensity"), std::string::npos) << problem;

  sensor_msgs::PointCloud2 none = c;
  none.fields.pop_back();
  problem.clear();
  const auto absent = readIntensity(none, problem);
  ASSERT_TRUE(absent);
  EXPECT_TRUE(absent->empty());
}
