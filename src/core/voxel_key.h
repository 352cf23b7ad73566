// Private to the core: packed integer voxel keys and their hash, shared by the voxel collapse
// the dense-sampling filter and the plane map.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher::detail {

/// Voxel index of coordinate v along one axis, offset by 2^20 and clamped to [0, 2^21 - 1].
/// (The product of two floats is exact in double, so every rounding here is exact: voxelKeys()
/// gives the same indices vectorised. NaN gives index 0.)
inline std::int64_t voxelIndex(float v, float inv) {
  const double c = std::floor(double(v) * double(inv)) + double(1 << 20);
  return std::int64_t(std::min(std::max(0.0, c), double((1 << 21) - 1)));
}

/// Packs three voxel indices of voxelIndex() (each in [0, 2^21 - 1]) into one key: 21 bits per
/// axis, +-2^20 voxels of edge 1/inv around the origin (clamped beyond).
inline std::uint64_t packVoxel(std::int64_t ix, std::int64_t iy, std::int64_t iz) {
  return std::uint64_t(ix) | (std::uint64_t(iy) << 21) | (std::uint64_t(iz) << 42);
}

/// The keys packVoxel(voxelIndex(x[i]), voxelIndex(y[i]), voxelIndex(z[i])) of n points into
/// keys[i], vectorised on the active SIMD path (voxel_keys.cpp).
void voxelKeys(const float* x, const float* y, const float* z, std::size_t n, float inv,
               std::uint64_t* keys);

/// Calls f(i, key) for every point i of `points` in order, the keys computed by voxelKeys() a
/// block at a time.
template <typename F>
void forEachVoxelKey(const PointArray& points, float inv, F&& f) {
  constexpr std::size_t kBlock = 512;
  std::uint64_t keys[kBlock];
  for (std::size_t begin = 0; begin < points.size(); begin += kBlock) {
    const std::size_t m = std::min(kBlock, points.size() - begin);
    voxelKeys(points.x.data() + begin, points.y.data() + begin, points.z.data() + begin, m, inv,
              keys);
    for (std::size_t k = 0; k < m; ++k) f(begin + k, keys[k]);
  }
}

/// Finaliser of MurmurHash3: spreads the packed key over the table's low bits.
inline std::uint64_t mixKey(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
}

/// Open-addressing hash map (linear probing) from packed keys to their insertion order
/// 0, 1, 2, ...: the index of a voxel in arrays the caller keeps. It starts small and doubles
/// when half full, so its memory follows the voxels, not the points (a table sized for every
/// point of a 64k-point scan was 1.5 MB to clear and fault in, most of a plane map's build).
class KeyIndex {
 public:
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};

  /// `expected`: a guess of the number of keys (the table grows past it).
  explicit KeyIndex(std::size_t expected = 0) { reset(expected); }
  /// Empties the map, keeping its memory when it is large enough for `expected` keys.
  void reset(std::size_t expected) {
    cap_ = std::max(capacityFor(expected), keys_.size());
    keys_.assign(cap_, kEmpty);
    index_.assign(cap_, kNone);
    size_ = 0;
  }
  /// The index of `key`, added as the next index if new; and whether it was new.
  std::pair<std::uint32_t, bool> insert(std::uint64_t key) {
    std::size_t h = mixKey(key) & (cap_ - 1);
    for (;; h = (h + 1) & (cap_ - 1)) {
      if (keys_[h] == key) return {index_[h], false};
      if (keys_[h] == kEmpty) break;
    }
    if (2 * (size_ + 1) > cap_) {
      rehash(2 * (std::size_t(size_) + 1));  // doubles the table
      return insert(key);
    }
    keys_[h] = key;
    index_[h] = size_;
    return {size_++, true};
  }
  /// The index of `key`, or kNone.
  std::uint32_t find(std::uint64_t key) const {
    for (std::size_t h = mixKey(key) & (cap_ - 1);; h = (h + 1) & (cap_ - 1)) {
      if (keys_[h] == key) return index_[h];
      if (keys_[h] == kEmpty) return kNone;
    }
  }
  std::uint32_t size() const { return size_; }
  std::size_t memoryBytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + index_.capacity() * sizeof(std::uint32_t);
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no packed key has bit 63 set
  /// The smallest power of two of at least 64 slots and at least 2 * n (half full at most).
  static std::size_t capacityFor(std::size_t n) {
    std::size_t cap = 64;
    while (cap < 2 * n) cap <<= 1;
    return cap;
  }
  /// A table of capacityFor(n) slots, with every key re-inserted.
  void rehash(std::size_t n) {
    const std::size_t cap = capacityFor(n);
    std::vector<std::uint64_t> keys(cap, kEmpty);
    std::vector<std::uint32_t> index(cap, kNone);
    for (std::size_t s = 0; s < keys_.size(); ++s) {
      if (keys_[s] == kEmpty) continue;
      std::size_t h = mixKey(keys_[s]) & (cap - 1);
      while (keys[h] != kEmpty) h = (h + 1) & (cap - 1);
      keys[h] = keys_[s];
      index[h] = index_[s];
    }
    keys_.swap(keys);
    index_.swap(index);
    cap_ = cap;
  }

  std::size_t cap_ = 0;
  std::uint32_t size_ = 0;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> index_;
};

}  // namespace cube_scan_matcher::detail
