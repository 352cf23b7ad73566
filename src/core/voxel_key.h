// Private to the core: packed integer voxel keys and their hash, shared by the voxel collapse
// and the dense-sampling filter.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace cube_scan_matcher::detail {

/// 21 bits per axis: +-2^20 voxels of edge 1/inv around the origin (clamped beyond).
inline std::uint64_t voxelKey(float x, float y, float z, float inv) {
  auto q = [inv](float v) {
    const double c = std::floor(double(v) * inv) + double(1 << 20);
    return std::uint64_t(std::min(std::max(c, 0.0), double((1 << 21) - 1)));
  };
  return q(x) | (q(y) << 21) | (q(z) << 42);
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
  /// Slots of the table: insert() returns one of [0, capacity()).
  std::size_t capacity() const { return cap_; }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no packed key has bit 63 set
  std::size_t cap_ = 64;
  std::vector<std::uint64_t> table_;
};

}  // namespace cube_scan_matcher::detail
