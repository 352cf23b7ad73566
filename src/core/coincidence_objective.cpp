#include "cube_scan_matcher/core/coincidence_objective.h"

#include <algorithm>

namespace cube_scan_matcher {

CoincidenceObjective::CoincidenceObjective(const CubeGrid& grid, const PointArray& scan)
    : grid_(grid), scan_(scan), work_(grid.bits()), idx_(kBlock) {
  hits_.resize(std::min(grid.occupiedCount(), scan.size()));
}

int CoincidenceObjective::evaluate(const Pose6& pose) {
  ++evaluations_;
  const Eigen::Isometry3d t = poseToIsometry(pose);
  const GridAffine g =
      grid_.affine(t.linear().cast<float>(), t.translation().cast<float>());
  const Eigen::Vector3f& dims = grid_.dimsF();
  std::uint64_t* const v = work_.data();
  std::int32_t* const hits = hits_.data();
  int j = 0;
  const std::size_t n = scan_.size();
  for (std::size_t begin = 0; begin < n; begin += kBlock) {
    const std::size_t m = std::min(kBlock, n - begin);
    computeCubeIndices(g, dims, scan_.x.data() + begin, scan_.y.data() + begin,
                       scan_.z.data() + begin, m, idx_.data());
    for (std::size_t i = 0; i < m; ++i) {
      const std::int32_t c = idx_[i];
      if (c < 0) continue;
      std::uint64_t& w = v[std::size_t(c) >> 6];
      const std::uint64_t bit = std::uint64_t{1} << (c & 63);
      if (w & bit) {  // a set cube hit for the first time: count it and clear it
        w &= ~bit;
        hits[j++] = c;
      }
    }
  }
  // Restore V from the hits (J <= l steps; the paper restores from L, l steps).
  for (int k = 0; k < j; ++k) {
    v[std::size_t(hits[k]) >> 6] |= std::uint64_t{1} << (hits[k] & 63);
  }
  return j;
}

}  // namespace cube_scan_matcher
