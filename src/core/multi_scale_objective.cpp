#include "cube_scan_matcher/core/multi_scale_objective.h"

#include <utility>

namespace cube_scan_matcher {

MultiScaleObjective::MultiScaleObjective(std::vector<CoincidenceObjective*> fine,
                                         CoincidenceObjective* coarse, double coarse_weight,
                                         const Eigen::Vector3d& pivot)
    : fine_(std::move(fine)), coarse_(coarse), coarse_weight_(coarse_weight), pivot_(pivot) {}

double MultiScaleObjective::operator()(const Vector6d& q) {
  const Pose6 p = pose(q);
  int fine_sum = 0, coarse_j = 0;
  for (CoincidenceObjective* j : fine_) fine_sum += (*j)(p);
  if (coarse_weight_ > 0.0) coarse_j = (*coarse_)(p);
  return double(fine_sum) + coarse_weight_ * double(coarse_j);
}

Pose6 MultiScaleObjective::pose(const Vector6d& q) const {
  Pose6 p = q;
  p.head<3>() = q.head<3>() - poseToIsometry(q).linear() * pivot_;
  return p;
}

Vector6d MultiScaleObjective::variable(const Pose6& pose) const {
  Vector6d q = pose;
  q.head<3>() = poseToIsometry(pose) * pivot_;
  return q;
}

Eigen::Vector3d centroid(const PointArray& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) c += Eigen::Vector3d(p.x[i], p.y[i], p.z[i]);
  return p.empty() ? c : Eigen::Vector3d(c / double(p.size()));
}

}  // namespace cube_scan_matcher
