#include "cube_scan_matcher/core/plane_map.h"

#include <cmath>
#include <stdexcept>
#include <thread>

#include <Eigen/Eigenvalues>

#include "reuse_memory.h"
#include "voxel_key.h"

namespace cube_scan_matcher {

namespace {
constexpr std::int64_t kMaxIndex = (std::int64_t{1} << 21) - 1;
}  // namespace

PlaneMap::PlaneMap() = default;
PlaneMap::~PlaneMap() = default;
PlaneMap::PlaneMap(PlaneMap&&) noexcept = default;
PlaneMap& PlaneMap::operator=(PlaneMap&&) noexcept = default;

PlaneMap::PlaneMap(const PointArray& reference, double voxel, int min_points,
                   double max_planarity, double min_spread) {
  rebuild(reference, voxel, min_points, max_planarity, min_spread);
}

void PlaneMap::rebuild(const PointArray& reference, double voxel, int min_points,
                       double max_planarity, double min_spread) {
  stats_.clear();  // an error below leaves an empty map (planeAt() finds nothing)
  if (!(voxel > 0.0)) throw std::invalid_argument("plane map voxel must be > 0 m");
  voxel_ = voxel;
  inv_ = float(1.0 / voxel);
  min_points_ = min_points;
  min_spread_ = min_spread;
  max_planarity_ = max_planarity;
  if (!keys_) keys_ = std::make_unique<detail::KeyIndex>();
  keys_->reset(reference.size() / 8);
  // Two passes: the voxel of every point, then the sums in one allocation (growing a vector of
  // 104-byte sums would copy it over and over).
  reserveForRebuild(voxel_of_, reference.size());
  voxel_of_.assign(reference.size(), detail::KeyIndex::kNone);
  detail::forEachVoxelKey(reference, inv_, [&](std::size_t i, std::uint64_t key) {
    const float x = reference.x[i], y = reference.y[i], z = reference.z[i];
    if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
      voxel_of_[i] = keys_->insert(key).first;
    }
  });
  reserveForRebuild(stats_, keys_->size());
  stats_.assign(keys_->size(), Stats());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (voxel_of_[i] == detail::KeyIndex::kNone) continue;
    Stats& s = stats_[voxel_of_[i]];
    const Eigen::Vector3d p(reference.x[i], reference.y[i], reference.z[i]);
    s.n += 1.0;
    s.sum += p;
    s.outer += p * p.transpose();
  }
  if (stats_.size() > fit_capacity_) {
    fit_capacity_ = stats_.size() + stats_.size() / 2;  // headroom: the next reference's size
    fit_ = std::make_unique<std::atomic<std::uint8_t>[]>(fit_capacity_);
  }
  for (std::size_t k = 0; k < stats_.size(); ++k) fit_[k].store(kUnknown, std::memory_order_relaxed);
  reserveForRebuild(planes_, stats_.size());
  planes_.resize(stats_.size());
}

std::uint8_t PlaneMap::fit(std::size_t index, std::int64_t ix, std::int64_t iy,
                          std::int64_t iz) const {
  Stats block;
  for (std::int64_t dz = -1; dz <= 1; ++dz) {
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const std::int64_t jx = ix + dx, jy = iy + dy, jz = iz + dz;
        if (jx < 0 || jy < 0 || jz < 0 || jx > kMaxIndex || jy > kMaxIndex || jz > kMaxIndex) {
          continue;
        }
        const std::uint32_t j = keys_->find(detail::packVoxel(jx, jy, jz));
        if (j == detail::KeyIndex::kNone) continue;
        const Stats& s = stats_[j];
        block.n += s.n;
        block.sum += s.sum;
        block.outer += s.outer;
      }
    }
  }
  if (block.n < double(min_points_)) return kNone;
  const Eigen::Vector3d mean = block.sum / block.n;
  const Eigen::Matrix3d cov = block.outer / block.n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  const Eigen::Vector3d& l = eig.eigenvalues();  // increasing
  if (!(l(0) <= max_planarity_ * l(1)) || !(l(1) > 0.0)) return kNone;
  if (l(1) < min_spread_ * min_spread_ * voxel_ * voxel_) return kNone;
  // The offset is the mean of the voxel's own points: on a curved surface (a tree's canopy, a
  // pillar) the mean of the whole block lies a sagitta inside the surface, and every point
  // near it would be pulled towards the centre of curvature (a bias along the direction the
  // objects are seen from); the voxel's own mean is 9 x closer to the surface.
  const Stats& own = stats_[index];
  planes_[index].mean = own.sum / own.n;
  planes_[index].normal = eig.eigenvectors().col(0).normalized();
  return kPlane;
}

std::uint8_t PlaneMap::fitOnce(std::size_t index, std::int64_t ix, std::int64_t iy,
                               std::int64_t iz) const {
  std::atomic<std::uint8_t>& state = fit_[index];
  std::uint8_t seen = kUnknown;
  if (state.compare_exchange_strong(seen, kFitting, std::memory_order_acquire)) {
    const std::uint8_t result = fit(index, ix, iy, iz);
    state.store(result, std::memory_order_release);
    return result;
  }
  while (seen == kFitting) {  // another thread fits it (a few microseconds)
    std::this_thread::yield();
    seen = state.load(std::memory_order_acquire);
  }
  return seen;
}

const LocalPlane* PlaneMap::planeAt(const Eigen::Vector3d& q) const {
  return planeOfVoxel(detail::voxelIndex(float(q.x()), inv_), detail::voxelIndex(float(q.y()), inv_),
                      detail::voxelIndex(float(q.z()), inv_));
}

const LocalPlane* PlaneMap::planeOfVoxel(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  if (stats_.empty() || ix < 0 || iy < 0 || iz < 0 || ix > kMaxIndex || iy > kMaxIndex ||
      iz > kMaxIndex) {
    return nullptr;
  }
  const std::uint32_t index = keys_->find(detail::packVoxel(ix, iy, iz));
  if (index == detail::KeyIndex::kNone) return nullptr;
  std::uint8_t state = fit_[index].load(std::memory_order_acquire);
  if (state == kUnknown || state == kFitting) state = fitOnce(index, ix, iy, iz);
  return state == kPlane ? &planes_[index] : nullptr;
}

std::size_t PlaneMap::memoryBytes() const {
  return (keys_ ? keys_->memoryBytes() : 0) + stats_.capacity() * sizeof(Stats) +
         voxel_of_.capacity() * sizeof(std::uint32_t) +
         fit_capacity_ * sizeof(std::atomic<std::uint8_t>) +
         planes_.capacity() * sizeof(LocalPlane);
}

}  // namespace cube_scan_matcher
