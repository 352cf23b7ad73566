// PCD/PLY reading for the ROS-free tools (PCL I/O lives here, never in the core).
#pragma once

#include <stdexcept>
#include <string>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher::io {

/// Reads a .pcd or .ply file with x, y, z fields. Throws std::runtime_error with a one-line
/// message naming the file and the problem (missing, unreadable, no x/y/z, no points).
pcl::PointCloud<pcl::PointXYZ>::Ptr loadCloud(const std::string& path);

/// Copies a PCL cloud into the core's structure-of-arrays layout (all points, NaN included).
PointArray toPointArray(const pcl::PointCloud<pcl::PointXYZ>& cloud);

}  // namespace cube_scan_matcher::io
