// Beyond the paper: the reference scan as local planes, for the point-to-plane polish
// (plane_polish.h). The reference points are summed per voxel of edge v (count, sum, sum of
// outer products: one pass, cheap enough to build with every reference); the plane of a voxel
// is fitted on first use and cached: its normal from the points of the 3 x 3 x 3 voxels
// around it (robust to range noise), its offset from the voxel's own points (close to a
// curved surface).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

namespace detail {
class KeyIndex;
}

/// A plane fitted to reference points: n . (q - mean) is the signed distance of q [m].
struct LocalPlane {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();    ///< centroid of the voxel's points [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit normal
};

class PlaneMap {
 public:
  /// An empty map: planeAt() finds nothing.
  PlaneMap();
  /// Sums the finite points of `reference` per voxel of edge `voxel` [m] (> 0). A block's plane
  /// is valid when it holds at least `min_points` points and is flat: smallest eigenvalue of
  /// the points' covariance <= max_planarity * the middle one (a line, e.g. one scan line
  /// across the window, has both alike and is no plane) and two-dimensional: its middle
  /// spread (square root of the middle eigenvalue) at least min_spread * voxel. A patch of one
  /// scan column seen at a grazing angle has the range noise, along the beam, as its second
  /// spread, and its "normal" would be perpendicular to the beam, not to the surface (tilted
  /// 18 deg along a tunnel's axis 15 m ahead: information the tunnel does not have).
  PlaneMap(const PointArray& reference, double voxel, int min_points, double max_planarity,
           double min_spread = 0.0);
  /// The same in place, reusing this map's memory. On error the map is left empty.
  void rebuild(const PointArray& reference, double voxel, int min_points, double max_planarity,
               double min_spread = 0.0);
  ~PlaneMap();
  PlaneMap(PlaneMap&&) noexcept;
  PlaneMap& operator=(PlaneMap&&) noexcept;

  /// The plane of the voxel holding q, or nullptr (no reference point there, too few, not flat).
  /// Fits and caches it on first use. Safe to call from several threads at once (each plane is
  /// fitted once, by the first thread that needs it; the others wait for it), but not while
  /// rebuild() runs.
  const LocalPlane* planeAt(const Eigen::Vector3d& q) const;
  /// The plane of voxel (ix, iy, iz) in voxelIndex() units (offset by 2^20), or nullptr.
  const LocalPlane* planeOfVoxel(std::int64_t ix, std::int64_t iy, std::int64_t iz) const;
  float inverseVoxel() const { return inv_; }

  double voxel() const { return voxel_; }
  /// Occupied voxels (0 for an empty map).
  std::size_t voxels() const { return stats_.size(); }
  /// Heap bytes of the map (hash table, voxel statistics, fitted planes).
  std::size_t memoryBytes() const;

 private:
  struct Stats {
    double n = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();  // sum of p p^T
  };
  enum Fit : std::uint8_t { kUnknown, kFitting, kPlane, kNone };
  /// Fits voxel `index`'s plane into planes_[index]; kPlane or kNone.
  std::uint8_t fit(std::size_t index, std::int64_t ix, std::int64_t iy, std::int64_t iz) const;
  /// Claims voxel `index` and fits it, or waits for the thread that claimed it first.
  std::uint8_t fitOnce(std::size_t index, std::int64_t ix, std::int64_t iy, std::int64_t iz) const;

  double voxel_ = 1.0;
  float inv_ = 1.0f;
  int min_points_ = 5;
  double min_spread_ = 0.0;
  double max_planarity_ = 0.1;
  std::unique_ptr<detail::KeyIndex> keys_;  // voxel key -> index into stats_
  std::vector<Stats> stats_;
  // Per voxel: a Fit state. Written with release once its plane is in planes_, read with
  // acquire, so a thread that sees kPlane sees the plane.
  mutable std::unique_ptr<std::atomic<std::uint8_t>[]> fit_;
  std::size_t fit_capacity_ = 0;
  mutable std::vector<LocalPlane> planes_;
  std::vector<std::uint32_t> voxel_of_;  // scratch of rebuild(): each point's voxel index
};

}  // namespace cube_scan_matcher
