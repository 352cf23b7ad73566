// Procedural scenes made of ray-castable primitives, for tests, the demo and benchmarks with
// exact truth (no external data). World frame: x forward, y left, z up, metres.
#pragma once

#include <cstddef>
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

/// The paper's four scene types (section 3.2), then six that robots meet beyond them:
///  - square: an open paved square, a few small objects, facades 55-75 m away (little structure);
///  - slope: steep (7 deg) rough terrain, bumps and rocks, few upright surfaces;
///  - forest: dense vegetation, hundreds of thin trunks and bushes of small spheres;
///  - tunnel: a straight featureless tunnel, 11 m wide and 6 m high (degenerate along x);
///  - wall: a long wall 3-4 m to the left filling half the view, an open field on the right;
///  - crowd: a street whose people and cars move between two sweeps (Scene::movers).
enum class SceneType { Hall, Urban, Park, Natural, Square, Slope, Forest, Tunnel, Wall, Crowd };
/// Every type, the paper's four first (kPaperSceneTypes of them).
const std::vector<SceneType>& allSceneTypes();
constexpr std::size_t kPaperSceneTypes = 4;
/// A type's name as above; throws std::invalid_argument for an unknown one.
SceneType sceneTypeFromString(const std::string& name);
std::string toString(SceneType type);
/// Scene names, with "paper", "robot" and "all" expanded (the tools' --scenes); throws
/// std::invalid_argument on an unknown name.
std::vector<std::string> expandSceneNames(const std::vector<std::string>& names);

/// A person (vertical cylinder, 0.25 m radius, 1.7 m tall) or a car (axis-aligned 4.5 x 1.8 x
/// 1.5 m box) at p0 (x, y on the ground, z of the ground) at t = 0, moving at v [m/s].
struct Mover {
  bool car = false;
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
};

class Scene {
 public:
  std::vector<Plane> planes;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;
  /// Objects that move: raycast() ignores them; at(t) turns them into primitives.
  std::vector<Mover> movers;
  /// No-return patches (dark or specular surfaces): a surface point inside one of these spheres
  /// gives no return. Empty unless added (addNoReturnPatches, a sensor artefact).
  std::vector<Sphere> no_return;

  /// Seeded procedural scene like the paper's four (section 3.2): equal seeds, equal worlds.
  /// The robot drives along +x from the origin, so content is laid out around that path.
  static Scene generate(SceneType type, std::uint64_t seed);

  /// The scene at time t [s]: the movers become cylinders and boxes at p0 + v t.
  Scene at(double t) const;

  /// True when p is inside (or within margin [m] of) a solid: no place for a scanner.
  bool insideSolid(const Eigen::Vector3d& p, double margin) const;

  /// Distance along the unit direction `dir` from `origin` to the first surface, or a
  /// negative value if the ray hits nothing within max_range. A hit inside a no_return sphere
  /// counts as no hit.
  double raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range) const;

  /// Height of the ground below (x, y) (for placing the robot), from the planes only.
  double groundHeight(double x, double y) const;
};

}  // namespace cube_scan_matcher::sim
