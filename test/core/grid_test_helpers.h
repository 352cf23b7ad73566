// Small grids for the CubeGrid and CoincidenceObjective tests.
#pragma once

#include <random>

#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher::test {

/// n points at the centres of n cubes of edge e in a row along x.
inline PointArray lineOfCubeCentres(int n, double e) {
  PointArray p;
  for (int i = 0; i < n; ++i) p.push_back(float(i * e), 0.f, 0.f);
  return p;
}

inline CubeGridSettings edge(double e) {
  CubeGridSettings s;
  s.cube_edge = e;
  return s;
}

/// A pure translation [m].
inline Pose6 shift(double x, double y = 0, double z = 0) {
  Pose6 p = Pose6::Zero();
  p.head<3>() << x, y, z;
  return p;
}

/// A small structured scene [m]: a 10 x 10 m floor, two walls 3 m high and three boxes, n
/// random points on them (seeded). A pose is recoverable from it in all six parameters.
inline PointArray cornerScene(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  PointArray p;
  for (int i = 0; i < n; ++i) {
    const float a = u(rng), b = u(rng);
    switch (i % 6) {
      case 0: case 1: p.push_back(10 * a, 10 * b, 0.f); break;  // floor
      case 2: p.push_back(10 * a, 0.f, 3 * b); break;            // wall y = 0
      case 3: p.push_back(0.f, 10 * a, 3 * b); break;            // wall x = 0
      case 4: p.push_back(2 + a, 5 + 1.5f * b, 1.2f * u(rng)); break;  // box
      default: p.push_back(6 + 0.8f * a, 2 + 0.6f * b, 2.f * u(rng)); break;  // box
    }
  }
  return p;
}

/// `points` moved by T (p' = T p).
inline PointArray transformed(const PointArray& points, const Eigen::Isometry3d& T) {
  PointArray out;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f q = Tf * points.point(i);
    out.push_back(q.x(), q.y(), q.z());
  }
  return out;
}

}  // namespace cube_scan_matcher::test
