#include "peer_methods.h"

#include <chrono>
#include <cmath>

#include <pcl/filters/voxel_grid.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

namespace cube_scan_matcher::tools {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
Eigen::Isometry3d toIso(const Eigen::Matrix4f& m) {
  Eigen::Isometry3d t;
  t.matrix() = m.cast<double>();
  return t;
}
}  // namespace

PeerResult runIcp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                  const Eigen::Isometry3d& guess) {
  PeerResult r;
  const auto t0 = Clock::now();
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setMaxCorrespondenceDistance(0.5);
  icp.setMaximumIterations(150);
  icp.setTransformationEpsilon(1e-6);  // (1e-3)^2: PCL compares squared changes
  icp.setInputSource(source);
  icp.setInputTarget(target);
  Cloud out;
  icp.align(out, guess.matrix().cast<float>());
  r.time_s = since(t0);
  r.estimate = toIso(icp.getFinalTransformation());
  return r;
}

PeerResult runNdt(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                  const Eigen::Isometry3d& guess) {
  PeerResult r;
  const auto t0 = Clock::now();
  Eigen::Matrix4f current = guess.matrix().cast<float>();
  for (float res : {2.0f, 1.0f, 0.5f}) {
    pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
    ndt.setResolution(res);
    ndt.setStepSize(0.1);
    ndt.setTransformationEpsilon(1e-6);
    ndt.setMaximumIterations(35);
    ndt.setInputSource(source);
    ndt.setInputTarget(target);
    Cloud out;
    ndt.align(out, current);
    current = ndt.getFinalTransformation();
    r.iterations += ndt.getFinalNumIteration();
  }
  r.time_s = since(t0);
  r.estimate = toIso(current);
  return r;
}

PeerResult runGicp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                   const Eigen::Isometry3d& guess) {
  PeerResult r;
  const auto t0 = Clock::now();
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setMaxCorrespondenceDistance(1.0);
  gicp.setInputSource(source);
  gicp.setInputTarget(target);
  Cloud out;
  gicp.align(out, guess.matrix().cast<float>());
  r.time_s = since(t0);
  r.estimate = toIso(gicp.getFinalTransformation());
  return r;
}

Cloud::Ptr toPcl(const PointArray& points) {
  auto cloud = pcl::make_shared<Cloud>();
  cloud->reserve(points.size());
  bool dense = true;
  for (std::size_t i = 0; i < points.size(); ++i) {
    cloud->push_back(pcl::PointXYZ(points.x[i], points.y[i], points.z[i]));
    dense = dense && std::isfinite(points.x[i]) && std::isfinite(points.y[i]) &&
            std::isfinite(points.z[i]);
  }
  cloud->is_dense = dense;
  return cloud;
}

Cloud::Ptr voxelCopy(const Cloud::ConstPtr& cloud, float leaf) {
  pcl::VoxelGrid<pcl::PointXYZ> vg;
  vg.setLeafSize(leaf, leaf, leaf);
  vg.setInputCloud(cloud);
  auto out = pcl::make_shared<Cloud>();
  vg.filter(*out);
  return out;
}

}  // namespace cube_scan_matcher::tools
