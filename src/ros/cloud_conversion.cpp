#include "cube_scan_matcher/ros/cloud_conversion.h"

#include <cstring>

#include <sensor_msgs/point_cloud2_iterator.h>

namespace cube_scan_matcher {
namespace {

const sensor_msgs::PointField* findField(const sensor_msgs::PointCloud2& cloud,
                                         const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

template <typename T>
T readAs(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // unaligned-safe
  return v;
}

}  // namespace

PointArray fromCloud(const sensor_msgs::PointCloud2& cloud, const Eigen::Isometry3d& transform) {
  const sensor_msgs::PointField* f[3] = {findField(cloud, "x"), findField(cloud, "y"),
                                         findField(cloud, "z")};
  if (!f[0] || !f[1] || !f[2]) {
    std::string names;
    for (const auto& field : cloud.fields) names += (names.empty() ? "" : ",") + field.name;
    throw CloudError("cloud has no x/y/z fields (fields: " + (names.empty() ? "none" : names) +
                     ")");
  }
  const std::uint8_t type = f[0]->datatype;
  if (f[1]->datatype != type || f[2]->datatype != type ||
      (type != sensor_msgs::PointField::FLOAT32 && type != sensor_msgs::PointField::FLOAT64)) {
    throw CloudError("cloud x/y/z must all be FLOAT32 or all FLOAT64 (datatypes " +
                     std::to_string(f[0]->datatype) + "," + std::to_string(f[1]->datatype) +
                     "," + std::to_string(f[2]->datatype) + ")");
  }
  const std::size_t size = type == sensor_msgs::PointField::FLOAT32 ? 4 : 8;
  for (const auto* field : f) {
    if (field->offset + size > cloud.point_step) {
      throw CloudError("cloud field " + field->name + " lies outside point_step");
    }
  }
  const std::size_t width = cloud.width, height = cloud.height;
  if (width * height == 0) return PointArray{};
  if (std::size_t(cloud.point_step) * width > cloud.row_step ||
      std::size_t(cloud.row_step) * height > cloud.data.size()) {
    throw CloudError("cloud data is truncated: " + std::to_string(cloud.data.size()) +
                     " bytes for " + std::to_string(width) + " x " + std::to_string(height) +
                     " points of " + std::to_string(cloud.point_step) + " bytes");
  }
  PointArray out;
  out.reserve(width * height);
  const Eigen::Matrix3d R = transform.linear();
  const Eigen::Vector3d t = transform.translation();
  for (std::size_t r = 0; r < height; ++r) {
    const std::uint8_t* row = cloud.data.data() + r * cloud.row_step;
    for (std::size_t c = 0; c < width; ++c) {
      const std::uint8_t* p = row + c * cloud.point_step;
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k) {
        v[k] = size == 4 ? double(readAs<float>(p + f[k]->offset))
                         : readAs<double>(p + f[k]->offset);
      }
      v = R * v + t;  // NaN stays NaN; the range filter drops it
      out.push_back(float(v.x()), float(v.y()), float(v.z()));
    }
  }
  return out;
}

namespace {

// Size in bytes of a PointField datatype; 0 for an unknown one.
std::size_t datatypeSize(std::uint8_t type) {
  switch (type) {
    case sensor_msgs::PointField::INT8:
    case sensor_msgs::PointField::UINT8: return 1;
    case sensor_msgs::PointField::INT16:
    case sensor_msgs::PointField::UINT16: return 2;
    case sensor_msgs::PointField::INT32:
    case sensor_msgs::PointField::UINT32:
    case sensor_msgs::PointField::FLOAT32: return 4;
    case sensor_msgs::PointField::FLOAT64: return 8;
    default: return 0;
  }
}

float readScalar(const std::uint8_t* p, std::uint8_t type) {
  switch (type) {
    case sensor_msgs::PointField::INT8: return float(readAs<std::int8_t>(p));
    case sensor_msgs::PointField::UINT8: return float(readAs<std::uint8_t>(p));
    case sensor_msgs::PointField::INT16: return float(readAs<std::int16_t>(p));
    case sensor_msgs::PointField::UINT16: return float(readAs<std::uint16_t>(p));
    case sensor_msgs::PointField::INT32: return float(readAs<std::int32_t>(p));
    case sensor_msgs::PointField::UINT32: return float(readAs<std::uint32_t>(p));
    case sensor_msgs::PointField::FLOAT32: return readAs<float>(p);
    default: return float(readAs<double>(p));
  }
}

// Every point's value of field `f` as float, after the layout checks fromCloud() makes.
std::vector<float> readField(const sensor_msgs::PointCloud2& cloud,
                             const sensor_msgs::PointField& f) {
  const std::size_t size = datatypeSize(f.datatype);
  if (size == 0) {
    throw CloudError("cloud field " + f.name + " has unknown datatype " +
                     std::to_string(f.datatype));
  }
  if (f.offset + size > cloud.point_step) {
    throw CloudError("cloud field " + f.name + " lies outside point_step");
  }
  const std::size_t width = cloud.width, height = cloud.height;
  if (width * height == 0) return {};
  if (std::size_t(cloud.point_step) * width > cloud.row_step ||
      std::size_t(cloud.row_step) * height > cloud.data.size()) {
    throw CloudError("cloud data is truncated");
  }
  std::vector<float> out;
  out.reserve(width * height);
  for (std::size_t r = 0; r < height; ++r) {
    const std::uint8_t* row = cloud.data.data() + r * cloud.row_step;
    for (std::size_t c = 0; c < width; ++c) {
      out.push_back(readScalar(row + c * cloud.point_step + f.offset, f.datatype));
    }
  }
  return out;
}

}  // namespace

std::vector<float> readFloatField(const sensor_msgs::PointCloud2& cloud, const std::string& name) {
  const sensor_msgs::PointField* f = findField(cloud, name);
  if (!f) return {};
  if (f->datatype != sensor_msgs::PointField::FLOAT32 &&
      f->datatype != sensor_msgs::PointField::FLOAT64) {
    throw CloudError("cloud field " + name + " (point times) must be FLOAT32 or FLOAT64 seconds, "
                     "datatype " + std::to_string(f->datatype));
  }
  return readField(cloud, *f);
}

std::optional<std::vector<float>> readIntensity(const sensor_msgs::PointCloud2& cloud,
                                                std::string& problem) {
  const sensor_msgs::PointField* f = findField(cloud, "intensity");
  if (!f) return std::vector<float>{};
  try {
    return readField(cloud, *f);
  } catch (const CloudError& e) {
    problem = e.what();
    return std::nullopt;
  }
}

sensor_msgs::PointCloud2 toCloud(const PointArray& points, const Eigen::Isometry3d& transform,
                                 const std_msgs::Header& header,
                                 const std::vector<float>* intensity) {
  if (intensity && intensity->size() != points.size()) {
    throw std::invalid_argument("toCloud: " + std::to_string(intensity->size()) +
                                " intensities for " + std::to_string(points.size()) + " points");
  }
  sensor_msgs::PointCloud2 cloud;
  cloud.header = header;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  if (intensity) {
    modifier.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                                  sensor_msgs::PointField::FLOAT32, "z", 1,
                                  sensor_msgs::PointField::FLOAT32, "intensity", 1,
                                  sensor_msgs::PointField::FLOAT32);
  } else {
    modifier.setPointCloud2FieldsByString(1, "xyz");
  }
  modifier.resize(points.size());
  cloud.height = 1;
  cloud.width = std::uint32_t(points.size());
  cloud.is_dense = true;
  // No iterator on an empty cloud: its constructor takes data.front() (UBSan: a reference to
  // null).
  if (points.empty()) return cloud;
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  const Eigen::Matrix3f R = transform.linear().cast<float>();
  const Eigen::Vector3f t = transform.translation().cast<float>();
  for (std::size_t i = 0; i < points.size(); ++i, ++x, ++y, ++z) {
    const Eigen::Vector3f v = R * Eigen::Vector3f(points.x[i], points.y[i], points.z[i]) + t;
    *x = v.x();
    *y = v.y();
    *z = v.z();
  }
  if (intensity) {
    sensor_msgs::PointCloud2Iterator<float> in(cloud, "intensity");
    for (std::size_t i = 0; i < points.size(); ++i, ++in) *in = (*intensity)[i];
  }
  return cloud;
}

}  // namespace cube_scan_matcher
