#include "cube_scan_matcher/io/cloud_io.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>

#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

namespace cube_scan_matcher::io {

pcl::PointCloud<pcl::PointXYZ>::Ptr loadCloud(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) throw std::runtime_error(path + ": no such file");
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path + ": not a regular file");
  std::string ext = path.substr(path.find_last_of('.') + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // our errors replace PCL's
  pcl::PCLPointCloud2 blob;
  int rc = -1;
  if (ext == "pcd") {
    rc = pcl::io::loadPCDFile(path, blob);
  } else if (ext == "ply") {
    rc = pcl::io::loadPLYFile(path, blob);
  } else {
    throw std::runtime_error(path + ": unknown extension '." + ext + "' (expected .pcd or .ply)");
  }
  if (rc < 0) throw std::runtime_error(path + ": cannot parse as " + ext + " (corrupt or truncated?)");
  for (const char* f : {"x", "y", "z"}) {
    const bool has = std::any_of(blob.fields.begin(), blob.fields.end(),
                                 [f](const pcl::PCLPointField& p) { return p.name == f; });
    if (!has) throw std::runtime_error(path + ": no '" + f + "' field");
  }
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::fromPCLPointCloud2(blob, *cloud);
  if (cloud->empty()) throw std::runtime_error(path + ": cloud has no points");
  return cloud;
}

PointArray toPointArray(const pcl::PointCloud<pcl::PointXYZ>& cloud) {
  PointArray out;
  out.reserve(cloud.size());
  for (const auto& p : cloud.points) out.push_back(p.x, p.y, p.z);
  return out;
}

}  // namespace cube_scan_matcher::io
