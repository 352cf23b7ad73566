// Private to the core: packed integer voxel keys and their hash, shared by the voxel collapse
// the dense-sampling filter and the plane map.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace cube_scan_matcher::detail {

/// Voxel index of coordinate v along one axis, offset by 2^20 and clamped to [0, 2^21 - 1].
inline std::int64_t voxelIndex(float v, float inv) {
  const double c = std::floor(double(v) * inv) + double(1 << 20);
  return std::int64_t(std::min(std::max(c, 0.0), double((1 << 21) - 1)));
}

/// Packs three voxel indices of voxelIndex() (each in [0, 2^21 - 1]) into one key.
inline std::uint64_t packVoxel(std::int64_t ix, std::int64_t iy, std::int64_t iz) {
  return std::uint64_t(ix) | (std::uint64_t(iy) << 21) | (std::uint64_t(iz) << 42);
}

/// 21 bits per axis: +-2^20 voxels of edge 1/inv around the origin (clamped beyond).
inline std::uint64_t voxelKey(float x, float y, float z, float inv) {
  return packVoxel(voxelIndex(x, inv), voxelIndex(y, inv), voxelIndex(z, inv));
}

/// Finaliser of MurmurHash3: spreads the packed key over the table's low bits.
inline std::uint64_t mixKey(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
}

/// Open-addressing hash set of packed keys (linear probing), sized for `n` distinct keys.
class KeySet {
 public:
  explicit KeySet(std::size_t n) {
    while (cap_ < 2 * n) cap_ <<= 1;
    table_.assign(cap_, kEmpty);
  }
  /// Inserts `key` if new. Returns its slot and whether it was new.
  std::pair<std::size_t, bool> insert(std::uint64_t key) {
    for (std::size_t h = mixKey(key) & (cap_ - 1);; h = (h + 1) & (cap_ - 1)) {
      if (table_[h] == key) return {h, false};
      if (table_[h] == kEmpty) {
        table_[h] = key;
        return {h, true};
      }
    }
  }
  /// The slot of `key`, or capacity() when it is not in the set.
  std::size_t find(std::uint64_t key) const {
    for (std::size_t h = mixKey(key) & (cap_ - 1);; h = (h + 1) & (cap_ - 1)) {
      if (table_[h] == key) return h;
      if (table_[h] == kEmpty) return cap_;
    }
  }
  /// Slots of the table: insert() returns one of [0, capacity()).
  std::size_t capacity() const { return cap_; }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no packed key has bit 63 set
  std::size_t cap_ = 64;
  std::vector<std::uint64_t> table_;
};

}  // namespace cube_scan_matcher::detail
