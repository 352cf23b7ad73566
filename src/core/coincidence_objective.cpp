#include "cube_scan_matcher/core/coincidence_objective.h"

#include <algorithm>

namespace cube_scan_matcher {

CoincidenceObjective::CoincidenceObjective(const CubeGrid& grid, const PointArray& scan)
    : grid_(grid), scan_(scan), work_(grid.bits()), idx_(kBlock) {
  // One spare word past V, always zero: outside points index into it and never count.
  outside_ = std::int32_t(work_.size() * 64);
  work_.push_back(0);
  // The counting loop stores every index and advances only on a hit: room for n + 1 stores.
  hits_.resize(scan.size() + 1);
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
                       scan_.z.data() + begin, m, outside_, idx_.data());
    // Branch-free: a set cube hit for the first time is counted and cleared; a clear cube,
    // a cube already hit, and the spare outside cube change nothing. Consecutive scan points
    // mostly hit the same word of V, so one stream would wait on its own store at every point;
    // four interleaved streams (quarters of the block) overlap those waits.
    auto count = [v, hits, &j](std::uint32_t c) {
      std::uint64_t& w = v[c >> 6];
      const std::uint64_t hit = (w >> (c & 63)) & 1u;
      w &= ~(hit << (c & 63));
      hits[j] = std::int32_t(c);
      j += int(hit);
    };
    const std::int32_t* id = idx_.data();
    const std::size_t q = m / 4;
    for (std::size_t i = 0; i < q; ++i) {
      count(std::uint32_t(id[i]));
      count(std::uint32_t(id[i + q]));
      count(std::uint32_t(id[i + 2 * q]));
      count(std::uint32_t(id[i + 3 * q]));
    }
    for (std::size_t i = 4 * q; i < m; ++i) count(std::uint32_t(id[i]));
  }
  // Restore V from the hits (J <= l steps; the paper restores from L, l steps).
  for (int k = 0; k < j; ++k) {
    v[std::size_t(hits[k]) >> 6] |= std::uint64_t{1} << (hits[k] & 63);
  }
  return j;
}

}  // namespace cube_scan_matcher
