// Structure-of-arrays point storage: three contiguous float arrays (metres), the layout the
// per-point loop of the objective reads with SIMD.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace cube_scan_matcher {

struct PointArray {
  std::vector<float> x, y, z;

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  void reserve(std::size_t n) {
    x.reserve(n);
    y.reserve(n);
    z.reserve(n);
  }
  void clear() {
    x.clear();
    y.clear();
    z.clear();
  }
  void push_back(float px, float py, float pz) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
  }
  Eigen::Vector3f point(std::size_t i) const { return {x[i], y[i], z[i]}; }
  /// A shared empty array (for objects that must always point at some array).
  static const PointArray& empty_array() {
    static const PointArray none;
    return none;
  }
};

}  // namespace cube_scan_matcher
