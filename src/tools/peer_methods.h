// PCL peers of the benchmark (paper section 3.3): ICP and NDT as the paper configured them,
// plus GICP. Each returns the estimate T_target_source for a guess, timed in the same process.
#pragma once

#include <string>

#include <Eigen/Geometry>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher::tools {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

struct PeerResult {
  Eigen::Isometry3d estimate = Eigen::Isometry3d::Identity();
  double time_s = 0.0;  ///< target set-up (k-d tree / NDT cells) plus alignment
  int iterations = 0;
};

/// ICP: 0.5 m max correspondence distance, 150 iterations, 1e-3 convergence (paper).
PeerResult runIcp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                  const Eigen::Isometry3d& guess);
/// NDT: cascade of 2 m, 1 m, 0.5 m cells, each started at the previous result (paper).
PeerResult runNdt(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                  const Eigen::Isometry3d& guess);
/// Generalized ICP with PCL's defaults but a 1 m max correspondence distance.
PeerResult runGicp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                   const Eigen::Isometry3d& guess);

/// The points as a PCL cloud (the peers' input).
Cloud::Ptr toPcl(const PointArray& points);

/// 0.2 m voxel-grid copy (centroids), as in the benchmark's "voxel" variants.
Cloud::Ptr voxelCopy(const Cloud::ConstPtr& cloud, float leaf);

}  // namespace cube_scan_matcher::tools
