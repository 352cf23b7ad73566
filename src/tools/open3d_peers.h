// Open3D peers of the sequence and pair benchmarks: point-to-plane ICP and
// generalized ICP from Debian's libopen3d-dev 0.16, with the same signature as the PCL peers
// (peer_methods.h) so the benchmarks chain them the same way. Built only when Open3D is found;
// open3dAvailable() says whether this build has them.
#pragma once

#include "peer_methods.h"

namespace cube_scan_matcher::tools {

/// True when the package was built with Open3D (the o3d-* methods exist).
bool open3dAvailable();

/// Point-to-plane ICP: target normals from up to 30 neighbours within 0.5 m (2.5 voxel leaves of
/// the 0.2 m copies), 1 m max correspondence distance, up to 50 iterations, stops at relative
/// fitness / RMSE changes below 1e-6. Throws std::runtime_error without Open3D.
PeerResult runOpen3dPointToPlane(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                                 const Eigen::Isometry3d& guess);
/// Generalized ICP (Open3D estimates each point's covariance from its 20 nearest neighbours),
/// 1 m max correspondence distance as PCL GICP, up to 50 iterations, same stop criteria.
PeerResult runOpen3dGicp(const Cloud::ConstPtr& source, const Cloud::ConstPtr& target,
                         const Eigen::Isometry3d& guess);

}  // namespace cube_scan_matcher::tools
