#include "cube_scan_matcher/core/multi_scale_objective.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cube_scan_matcher {

MultiScaleObjective::MultiScaleObjective(std::vector<CoincidenceObjective*> fine,
                                         CoincidenceObjective* coarse, double coarse_weight,
                                         const Eigen::Vector3d& pivot)
    : fine_(std::move(fine)), coarse_(coarse), coarse_weight_(coarse_weight), pivot_(pivot) {
  all_ = fine_;
  if (coarse_weight_ > 0.0) all_.push_back(coarse_);
}

double MultiScaleObjective::operator()(const Vector6d& q) {
  const Pose6 p = pose(q);
  int fine_sum = 0, coarse_j = 0;
  together_last_ = evaluateTogether(p, fine_sum, coarse_j);
  if (!together_last_) {
    for (CoincidenceObjective* j : fine_) fine_sum += (*j)(p);
    if (coarse_weight_ > 0.0) coarse_j = (*coarse_)(p);
  }
  return double(fine_sum) + coarse_weight_ * double(coarse_j);
}

bool MultiScaleObjective::evaluateTogether(const Pose6& p, int& fine_sum, int& coarse_j) {
  // The grids' affines at p: their rotation parts must be power-of-two multiples of the first
  // one's, entry for entry (edges E / 2^k), and the objectives must share one scan.
  if (all_.size() < 2) return false;
  const PointArray* scan = all_.front()->scan();
  if (!scan || scan->empty()) return false;
  const Eigen::Isometry3d t = poseToIsometry(p);
  const Eigen::Matrix3f r = t.linear().cast<float>();
  const Eigen::Vector3f tr = t.translation().cast<float>();
  affines_.resize(all_.size());
  scales_.resize(all_.size());
  for (std::size_t k = 0; k < all_.size(); ++k) {
    if (all_[k]->scan() != scan) return false;
    affines_[k] = all_[k]->grid().affine(r, tr);
    const float s =
        float(1.0 / all_[k]->grid().edge()) / float(1.0 / all_.front()->grid().edge());
    int e = 0;
    if (!(std::frexp(s, &e) == 0.5f)) return false;  // not a power of two
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (!(affines_[k].a[i][j] == s * affines_[0].a[i][j])) return false;
      }
    }
    scales_[k] = s;
  }
  // One rotation per block, then the indices and the count on each grid.
  constexpr std::size_t kBlock = CoincidenceObjective::kBlock;
  ux_.resize(kBlock), uy_.resize(kBlock), uz_.resize(kBlock), idx_.resize(kBlock);
  for (CoincidenceObjective* o : all_) o->startCount();
  for (std::size_t begin = 0; begin < scan->size(); begin += kBlock) {
    const std::size_t m = std::min(kBlock, scan->size() - begin);
    rotatePoints(affines_[0].a, scan->x.data() + begin, scan->y.data() + begin,
                 scan->z.data() + begin, m, ux_.data(), uy_.data(), uz_.data());
    for (std::size_t k = 0; k < all_.size(); ++k) {
      cubeIndicesFromRotated(scales_[k], affines_[k].b, all_[k]->grid().dimsF(), ux_.data(),
                             uy_.data(), uz_.data(), m, all_[k]->outsideIndex(), idx_.data());
      all_[k]->countBlock(idx_.data(), m);
    }
  }
  fine_sum = 0;
  for (CoincidenceObjective* o : fine_) fine_sum += o->finishCount();
  coarse_j = coarse_weight_ > 0.0 ? coarse_->finishCount() : 0;
  return true;
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
