// Procedural scenes made of ray-castable primitives, for tests, the demo and benchmarks with
// exact truth (no external data). World frame: x forward, y left, z up, metres.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace cube_scan_matcher::sim {

struct Plane {  ///< n . p = d, n unit
  Eigen::Vector3d n;
  double d;
};
struct Box {  ///< axis-aligned
  Eigen::Vector3d lo, hi;
};
struct Cylinder {  ///< vertical axis through (cx, cy), z in [z0, z1]
  double cx, cy, r, z0, z1;
};
struct Sphere {
  Eigen::Vector3d c;
  double r;
};

enum class SceneType { Hall, Urban, Park, Natural };
/// "hall", "urban", "park", "natural"; throws std::invalid_argument otherwise.
SceneType sceneTypeFromString(const std::string& name);
std::string toString(SceneType type);

class Scene {
 public:
  std::vector<Plane> planes;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;

  /// Seeded procedural scene like the paper's four (section 3.2): equal seeds, equal worlds.
  /// The robot drives along +x from the origin, so content is laid out around that path.
  static Scene generate(SceneType type, std::uint64_t seed);

  /// Distance along the unit direction `dir` from `origin` to the first surface, or a
  /// negative value if the ray hits nothing within max_range.
  double raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range) const;

  /// Height of the ground below (x, y) (for placing the robot), from the planes only.
  double groundHeight(double x, double y) const;
};

}  // namespace cube_scan_matcher::sim
