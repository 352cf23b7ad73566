// sensor_msgs/PointCloud2 <-> the core's PointArray. Reads float32 and float64 x/y/z, checks
// the message layout before touching its bytes, and never crashes on a malformed cloud.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <sensor_msgs/PointCloud2.h>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

/// A cloud that cannot be read (no x/y/z field, unsupported type, truncated data); what()
/// says which.
class CloudError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// All width * height points of `cloud`, NaN included, transformed by `transform` (into the
/// frame the caller wants). Throws CloudError.
PointArray fromCloud(const sensor_msgs::PointCloud2& cloud,
                     const Eigen::Isometry3d& transform = Eigen::Isometry3d::Identity());

/// The `field` of every point as float (FLOAT32 or FLOAT64 seconds: the point times), width *
/// height of them in fromCloud()'s order; empty if the cloud has no such field. Throws
/// CloudError if the field has another type or lies outside point_step (the layout is checked
/// as fromCloud() does).
std::vector<float> readFloatField(const sensor_msgs::PointCloud2& cloud, const std::string& field);

/// Every point's "intensity" converted to float from whatever scalar type the driver used
/// (uint8/16, float32, ...), in fromCloud()'s order; empty if the cloud has none. nullopt
/// with `problem` set when the field cannot be read: the scan is still usable without it.
std::optional<std::vector<float>> readIntensity(const sensor_msgs::PointCloud2& cloud,
                                                std::string& problem);

/// A dense float32 x/y/z cloud of `points` transformed by `transform`, with a float32
/// "intensity" field when `intensity` (one per point) is given. Throws std::invalid_argument
/// on a size mismatch.
sensor_msgs::PointCloud2 toCloud(const PointArray& points, const Eigen::Isometry3d& transform,
                                 const std_msgs::Header& header,
                                 const std::vector<float>* intensity = nullptr);

}  // namespace cube_scan_matcher
