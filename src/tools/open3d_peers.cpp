#include "open3d_peers.h"

#include <chrono>
#include <stdexcept>

#ifdef CSM_HAVE_OPEN3D
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GeneralizedICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#endif

namespace cube_scan_matcher::tools {

#ifdef CSM_HAVE_OPEN3D
namespace {
namespace reg = open3d::pipelines::registration;
using Clock = std::chrono::steady_clock;

constexpr double kMaxCorrespondence = 1.0;  // [m], as PCL GICP in peer_methods.cpp
constexpr double kNormalRadius = 0.5;       // [m]
constexpr int kNormalNeighbours = 30;
const reg::ICPConvergenceCriteria kCriteria(1e-6, 1e-6, 50);

open3d::geometry::PointCloud toOpen3d(const Cloud& cloud) {
  open3d::geometry::PointCloud out;
  out.points_.reserve(cloud.size());
  for (const auto& p : cloud) out.points_.emplace_back(p.x, p.y, p.z);
  return out;
}

PeerResult finish(const reg::RegistrationResult& result, Clock::time_point t0) {
  PeerResult r;
  r.time_s = std::chrono::duration<double>(Clock::now() - t0).count();
  r.estimate.matrix() = result.transformation_;
  return r;
}
}  // namespace

bool open3dAvailable() { return true; }

PeerResult runOpen3dPointToPlane(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                                 const Eigen::Isometry3d& guess) {
  const auto t0 = Clock::now();
  const auto src = toOpen3d(*source);
  auto tgt = toOpen3d(*target);
  tgt.EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(kNormalRadius, kNormalNeighbours));
  return finish(reg::RegistrationICP(src, tgt, kMaxCorrespondence, guess.matrix(),
                                     reg::TransformationEstimationPointToPlane(), kCriteria),
                t0);
}

PeerResult runOpen3dGicp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                         const Eigen::Isometry3d& guess) {
  const auto t0 = Clock::now();
  return finish(reg::RegistrationGeneralizedICP(toOpen3d(*source), toOpen3d(*target),
                                                kMaxCorrespondence, guess.matrix(),
                                                reg::TransformationEstimationForGeneralizedICP(),
                                                kCriteria),
                t0);
}
#else
namespace {
[[noreturn]] void missing() {
  throw std::runtime_error("this build has no Open3D peers: install libopen3d-dev and rebuild");
}
}  // namespace

bool open3dAvailable() { return false; }
PeerResult runOpen3dPointToPlane(const Cloud::ConstPtr&, const Cloud::ConstPtr&,
                                 const Eigen::Isometry3d&) {
  missing();
}
PeerResult runOpen3dGicp(const Cloud::ConstPtr&, const Cloud::ConstPtr&, const Eigen::Isometry3d&) {
  missing();
}
#endif

}  // namespace cube_scan_matcher::tools
