// Coarse binary cubes of a reference scan (paper section 2.1, eqs. 3-6).
//
// The grid spans the axis-aligned bounding box of the reference points. A point's integer grid
// coordinates are I_k = round((k - k_min) / E) for k in {x, y, z} (eq. 6), and its linear index
// is I = Ix + Iy*Nx + Iz*Nx*Ny (eq. 5). Erratum: with round(), Ix runs 0..Ixmax *inclusive*, so
// there are Nx = Ixmax + 1 cubes along x (eq. 3 writes v = Ixmax*Iymax*Izmax; here
// v = Nx*Ny*Nz). V holds one bit per cube; L lists the indices of the set cubes (l = |L|).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "cube_scan_matcher/core/large_buffer.h"
#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

struct CubeGridSettings {
  double cube_edge = 0.5;  ///< E [m], in (0, 100]. The paper recommends 0.3-0.5 m.
  /// Memory guard: largest allowed v = Nx*Ny*Nz [cubes = bits], in [1, 2^31]. The default
  /// 2^31 bits is 256 MiB; a larger grid (absurd extent or tiny E) is refused with an error.
  std::uint64_t max_cubes = std::uint64_t{1} << 31;
  /// Beyond the paper: an objective's working copy of V uses one byte per cube (about 1.8x
  /// faster counting; docs/experiments.md, "Where the time went") for grids of up to this
  /// many cubes, and V's one bit per cube above. Each thread of the search owns one working
  /// copy per grid, so this bounds that memory at max_byte_cubes bytes per copy. 0 = always
  /// bits. In [0, 2^28].
  std::uint64_t max_byte_cubes = std::uint64_t{1} << 22;
  /// Beyond the paper: the grid origin is moved to min - origin_shift * E (same on all axes),
  /// in [0, 1). Grids with different shifts cut space at different places; summing their J
  /// smooths the aliasing of a single grid. 0 = the paper's grid.
  double origin_shift = 0.0;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const CubeGridSettings& settings);

/// Why a grid could not be built.
class CubeGridError : public std::runtime_error {
 public:
  enum class Code { EmptyReference, NonFiniteReference, TooManyCubes };
  CubeGridError(Code code, const std::string& what) : std::runtime_error(what), code_(code) {}
  Code code() const { return code_; }

 private:
  Code code_;
};

/// Affine map from a point (metres) to continuous grid coordinates plus 0.5, so that
/// floor(A p + b) = round((R p + t - min) / E): one multiply-add chain per axis in the hot loop.
struct GridAffine {
  float a[3][3];
  float b[3];
};

class CubeGrid {
 public:
  CubeGrid() = default;

  /// Builds V and L from the reference points (which must be finite: filter them first).
  /// Throws CubeGridError (empty input, non-finite point, v above settings.max_cubes).
  static CubeGrid build(const PointArray& reference, const CubeGridSettings& settings);
  /// The same in place, reusing this grid's memory (no page to fault in when the new grid is
  /// no larger). On error the grid is left empty.
  void rebuild(const PointArray& reference, const CubeGridSettings& settings);

  double edge() const { return edge_; }
  const Eigen::Vector3d& minCorner() const { return min_; }
  const Eigen::Vector3d& maxCorner() const { return max_; }
  /// Cubes per axis (Ixmax + 1, ...).
  const Eigen::Vector3i& dims() const { return dims_; }
  /// v: number of cubes (bits of V).
  std::uint64_t cubeCount() const { return std::uint64_t(dims_.x()) * dims_.y() * dims_.z(); }
  /// l: number of set cubes (length of L).
  std::size_t occupiedCount() const { return list_.size(); }
  /// Whether an objective's working copy of V uses a byte per cube (see max_byte_cubes).
  bool bytePerCube() const { return cubeCount() <= max_byte_cubes_; }

  /// Linear index (eq. 5) of the cube holding p = R q + t, or -1 if outside the grid.
  std::int64_t index(const Eigen::Vector3f& p) const;
  bool occupied(std::int64_t index) const {
    return index >= 0 && ((bits_[std::size_t(index) >> 6] >> (index & 63)) & 1u);
  }
  const LargeBuffer<std::uint64_t>& bits() const { return bits_; }
  const std::vector<std::int32_t>& list() const { return list_; }
  /// Heap bytes of V and L.
  std::size_t memoryBytes() const {
    return bits_.capacity() * sizeof(std::uint64_t) + list_.capacity() * sizeof(std::int32_t);
  }

  /// The map used by the objective for a candidate rotation R and translation t (float).
  GridAffine affine(const Eigen::Matrix3f& rotation, const Eigen::Vector3f& translation) const;
  /// Grid extent as floats for the in-grid test 0 <= a < N.
  const Eigen::Vector3f& dimsF() const { return dims_f_; }

 private:
  double edge_ = 0.0;
  std::uint64_t max_byte_cubes_ = 0;
  Eigen::Vector3d min_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  Eigen::Vector3f dims_f_ = Eigen::Vector3f::Zero();
  LargeBuffer<std::uint64_t> bits_;  ///< V, 64 cubes per word.
  std::vector<std::int32_t> list_;   ///< L, unsorted indices of set cubes.
};

/// Eq. (5)-(6) for a block of points: idx[i] = linear index of A p_i + b, or `outside` for a
/// point outside the grid. The per-point loop of the method: contiguous floats in, int32 out,
/// vectorised; the objective passes the index of a spare always-zero cube as `outside`, so its
/// counting loop needs no branch.
void computeCubeIndices(const GridAffine& affine, const Eigen::Vector3f& dims, const float* x,
                        const float* y, const float* z, std::size_t n, std::int32_t outside,
                        std::int32_t* idx);

/// computeCubeIndices in two steps, for several grids evaluated at one pose (the refine's):
/// u = A p [cubes] for a rotation part A (GridAffine::a of one grid) ...
void rotatePoints(const float (&a)[3][3], const float* x, const float* y, const float* z,
                  std::size_t n, float* ux, float* uy, float* uz);
/// ... then per grid the indices of s u + b, with b that grid's GridAffine::b. When that grid's
/// GridAffine::a equals s A entry for entry and s is a power of two, the indices equal
/// computeCubeIndices' with that grid's affine (the same roundings).
void cubeIndicesFromRotated(float s, const float (&b)[3], const Eigen::Vector3f& dims,
                            const float* ux, const float* uy, const float* uz, std::size_t n,
                            std::int32_t outside, std::int32_t* idx);

}  // namespace cube_scan_matcher
