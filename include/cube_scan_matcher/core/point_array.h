// Structure-of-arrays point storage: three contiguous float arrays (metres), the layout the
// per-point loop of the objective reads with SIMD.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

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

/// Appends T * p for every point p of `in` to `out` (rotation and translation in float).
inline void appendTransformed(PointArray& out, const PointArray& in, const Eigen::Isometry3d& T) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  out.reserve(out.size() + in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3f q = R * in.point(i) + t;
    out.push_back(q.x(), q.y(), q.z());
  }
}

}  // namespace cube_scan_matcher
