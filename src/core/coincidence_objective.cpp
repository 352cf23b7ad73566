#include "cube_scan_matcher/core/coincidence_objective.h"

#include <algorithm>

#include "reuse_memory.h"

namespace cube_scan_matcher {

CoincidenceObjective::CoincidenceObjective(const CubeGrid& grid) : grid_(&grid), idx_(kBlock) {
  initWorkingCopy();
}

void CoincidenceObjective::initWorkingCopy() {
  // Both copies are all zero on entry (new, or cleared by setGrid), so only growth is written:
  // 1 for each set cube of L, and a spare always-zero cube past the grid into which outside
  // points index. The copy of the other mode keeps its memory (all zero): a reference whose
  // size crosses max_byte_cubes and back does not allocate and fault in fresh pages.
  const CubeGrid& grid = *grid_;
  byte_mode_ = grid.bytePerCube();
  if (byte_mode_) {
    outside_ = std::int32_t(grid.cubeCount());
    reserveForRebuild(bytes_, std::size_t(grid.cubeCount()) + 1);  // all zero, or dropped
    bytes_.resize(std::size_t(grid.cubeCount()) + 1, 0);
    for (std::int32_t c : grid.list()) bytes_[std::size_t(c)] = 1;
  } else {
    const std::size_t words = grid.bits().size();
    outside_ = std::int32_t(words * 64);
    reserveForRebuild(bits_, words + 1);
    bits_.resize(words + 1, 0);
    for (std::int32_t c : grid.list()) bits_[std::size_t(c) >> 6] |= std::uint64_t{1} << (c & 63);
  }
}

void CoincidenceObjective::setGrid(const CubeGrid& grid) {
  // Between evaluations the working copy equals the old V: clearing the old L zeroes it.
  for (std::int32_t c : grid_->list()) {
    if (bytePerCube()) {
      bytes_[std::size_t(c)] = 0;
    } else {
      bits_[std::size_t(c) >> 6] = 0;
    }
  }
  grid_ = &grid;
  scan_ = nullptr;
  initWorkingCopy();
}

CoincidenceObjective::CoincidenceObjective(const CubeGrid& grid, const PointArray& scan)
    : CoincidenceObjective(grid) {
  setScan(scan);
}

void CoincidenceObjective::setScan(const PointArray& scan) {
  scan_ = &scan;
  // The bit-mode counting loop stores every index and advances only on a hit: n + 1 stores.
  if (!bytePerCube() && hits_.size() < scan.size() + 1) hits_.resize(scan.size() + 1);
}

bool CoincidenceObjective::workingCopyRestored() const {
  if (bytePerCube()) {
    std::size_t set = 0;
    for (std::size_t c = 0; c < bytes_.size(); ++c) {
      if (bytes_[c] > 1 || (bytes_[c] && !grid_->occupied(std::int64_t(c)))) return false;
      set += bytes_[c];
    }
    return set == grid_->occupiedCount() && bytes_.back() == 0;
  }
  return std::equal(grid_->bits().begin(), grid_->bits().end(), bits_.begin()) &&
         bits_.back() == 0;
}

template <typename CountBlock>
void CoincidenceObjective::forEachIndexBlock(const GridAffine& g, CountBlock&& count_block) {
  const Eigen::Vector3f& dims = grid_->dimsF();
  const PointArray& scan = *scan_;
  for (std::size_t begin = 0; begin < scan.size(); begin += kBlock) {
    const std::size_t m = std::min(kBlock, scan.size() - begin);
    computeCubeIndices(g, dims, scan.x.data() + begin, scan.y.data() + begin,
                       scan.z.data() + begin, m, outside_, idx_.data());
    count_block(idx_.data(), m);
  }
}

int CoincidenceObjective::evaluate(const Pose6& pose) {
  if (!scan_ || scan_->empty()) return 0;
  const Eigen::Isometry3d t = poseToIsometry(pose);
  const GridAffine g = grid_->affine(t.linear().cast<float>(), t.translation().cast<float>());
  startCount();
  if (bytePerCube()) {
    forEachIndexBlock(g, [this](const std::int32_t* id, std::size_t m) { countBytes(id, m); });
  } else {
    forEachIndexBlock(g, [this](const std::int32_t* id, std::size_t m) { countBits(id, m); });
  }
  return finishCount();
}

void CoincidenceObjective::countBlock(const std::int32_t* idx, std::size_t m) {
  if (bytePerCube()) {
    countBytes(idx, m);
  } else {
    countBits(idx, m);
  }
}

void CoincidenceObjective::countBytes(const std::int32_t* id, std::size_t m) {
  std::uint8_t* const v = bytes_.data();
  int j = j_;
  // A set cube hit for the first time counts 1 and is cleared; a clear cube, a cube already
  // hit and the spare outside cube count 0. The store does not depend on the load, so
  // consecutive points in the same cube do not wait on each other.
  for (std::size_t i = 0; i < m; ++i) {
    std::uint8_t& cube = v[std::uint32_t(id[i])];
    j += cube;
    cube = 0;
  }
  j_ = j;
}

void CoincidenceObjective::countBits(const std::int32_t* id, std::size_t m) {
  std::uint64_t* const v = bits_.data();
  std::int32_t* const hits = hits_.data();
  int j = j_;
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
  const std::size_t q = m / 4;
  for (std::size_t i = 0; i < q; ++i) {
    count(std::uint32_t(id[i]));
    count(std::uint32_t(id[i + q]));
    count(std::uint32_t(id[i + 2 * q]));
    count(std::uint32_t(id[i + 3 * q]));
  }
  for (std::size_t i = 4 * q; i < m; ++i) count(std::uint32_t(id[i]));
  j_ = j;
}

int CoincidenceObjective::finishCount() {
  if (bytePerCube()) {
    // Restore from L (the paper's way, l stores): cheaper than recording the J hits in the loop.
    std::uint8_t* const v = bytes_.data();
    for (std::int32_t c : grid_->list()) v[std::size_t(c)] = 1;
  } else {
    // Restore V from the hits (J <= l steps; the paper restores from L, l steps).
    std::uint64_t* const v = bits_.data();
    for (int k = 0; k < j_; ++k) {
      v[std::size_t(hits_[std::size_t(k)]) >> 6] |= std::uint64_t{1} << (hits_[std::size_t(k)] & 63);
    }
  }
  return j_;
}

}  // namespace cube_scan_matcher
