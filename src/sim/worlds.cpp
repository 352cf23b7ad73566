// The procedural worlds of the simulator (scene.h): the paper's four scene types and six that
// robots meet beyond them. Every world is seeded: equal (type, seed), equal world.
#include <cmath>
#include <random>

#include "cube_scan_matcher/sim/scene.h"

namespace cube_scan_matcher::sim {
namespace {

struct Builder {
  Scene s;
  std::mt19937_64 rng;
  explicit Builder(std::uint64_t seed) : rng(seed) {}
  double u(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  void ground(double slope_x = 0.0, double slope_y = 0.0) {
    s.planes.push_back({Eigen::Vector3d(-slope_x, -slope_y, 1.0).normalized(), 0.0});
  }
  void box(double x, double y, double z, double sx, double sy, double sz) {
    s.boxes.push_back({Eigen::Vector3d(x - sx / 2, y - sy / 2, z), Eigen::Vector3d(x + sx / 2, y + sy / 2, z + sz)});
  }
  void tree(double x, double y, double z) {
    const double h = u(2.5, 5.0);
    s.cylinders.push_back({x, y, u(0.12, 0.35), z - 0.5, z + h});
    s.spheres.push_back({Eigen::Vector3d(x, y, z + h + u(0.5, 1.2)), u(1.2, 2.5)});
  }
  /// A street along x: building blocks with gaps on both sides, poles, parked cars, walls.
  void street() {
    ground();
    for (int side : {-1, 1}) {
      for (double x = -30; x < 160;) {
        const double len = u(8, 25), depth = u(8, 20), h = u(6, 25);
        const double y = side * (u(9, 13) + depth / 2);
        box(x + len / 2, y, 0, len, depth, h);
        x += len + u(2, 10);
      }
      for (double x = -25; x < 155; x += u(7, 12)) s.cylinders.push_back({x, side * u(6.5, 7.5), 0.12, 0, u(4, 8)});
      for (int i = 0; i < 14; ++i) box(u(-25, 150), side * u(4.5, 5.5), 0, u(3.8, 4.8), 1.8, u(1.3, 1.8));
    }
    for (int i = 0; i < 6; ++i) box(u(-20, 150), u(-8, 8), 0, u(0.3, 0.6), u(2, 6), u(0.8, 1.5));
  }
  /// A bump or rock: a sphere of radius r at (x, y), its top `above` [m] over the ground.
  void bump(double x, double y, double r, double above) {
    s.spheres.push_back({Eigen::Vector3d(x, y, s.groundHeight(x, y) + above - r), r});
  }
};
}  // namespace

Scene Scene::generate(SceneType type, std::uint64_t seed) {
  Builder b(seed * 7919 + std::uint64_t(type));
  switch (type) {
    case SceneType::Hall: {
      // A large hall, 160 x 30 m and 7 m high, with columns, furniture and partitions.
      b.ground();
      b.s.planes.push_back({Eigen::Vector3d(0, 0, -1), -7.0});  // ceiling at z = 7
      b.box(60, 16, 0, 170, 1, 7);   // left wall
      b.box(60, -16, 0, 170, 1, 7);  // right wall
      b.box(-25, 0, 0, 1, 32, 7);    // back wall
      b.box(145, 0, 0, 1, 32, 7);    // front wall
      for (double x = -15; x < 140; x += 12) {
        b.s.cylinders.push_back({x, 8.0, 0.35, 0, 7});
        b.s.cylinders.push_back({x + 6, -8.0, 0.35, 0, 7});
      }
      for (int i = 0; i < 45; ++i) {
        const double x = b.u(-20, 140), y = b.u(-14, 14);
        if (std::abs(y) < 2.5) continue;  // keep the robot's aisle free
        b.box(x, y, 0, b.u(0.5, 3), b.u(0.5, 3), b.u(0.5, 2.5));
      }
      for (int i = 0; i < 8; ++i) b.box(b.u(-10, 130), b.u(8, 13) * (i % 2 ? 1 : -1), 0, b.u(3, 8), 0.2, b.u(2, 3.5));
      break;
    }
    case SceneType::Urban: b.street(); break;
    case SceneType::Park: {
      // Gently sloped lawn with trees (trunks and canopies), benches and a few lamp posts.
      b.ground(0.03, -0.02);
      for (int i = 0; i < 110; ++i) {
        const double x = b.u(-30, 160), y = b.u(-45, 45);
        if (std::abs(y) < 3) continue;
        b.tree(x, y, b.s.groundHeight(x, y));
      }
      for (int i = 0; i < 25; ++i) {
        const double x = b.u(-30, 160), y = b.u(-30, 30);
        if (std::abs(y) < 3) continue;
        b.box(x, y, b.s.groundHeight(x, y) - 0.2, b.u(1.5, 2.0), 0.6, 1.0);
      }
      for (double x = -20; x < 160; x += 15) b.s.cylinders.push_back({x, 4.0, 0.1, -1, b.s.groundHeight(x, 4) + 4});
      break;
    }
    case SceneType::Natural: {
      // Uneven sloped terrain (buried spheres make hills and hollows), rocks, sparse bushes.
      b.ground(-0.04, 0.05);
      for (int i = 0; i < 40; ++i) {
        const double x = b.u(-40, 170), y = b.u(-60, 60), r = b.u(8, 30);
        if (std::abs(y) < r * 0.4 + 4) continue;
        b.s.spheres.push_back({Eigen::Vector3d(x, y, b.s.groundHeight(x, y) - r + b.u(0.5, 3.0)), r});
      }
      for (int i = 0; i < 120; ++i) {
        const double x = b.u(-30, 160), y = b.u(-40, 40), r = b.u(0.2, 1.4);
        if (std::abs(y) < 2 + r) continue;
        b.s.spheres.push_back({Eigen::Vector3d(x, y, b.s.groundHeight(x, y) + r * 0.3), r});
      }
      for (int i = 0; i < 50; ++i) {
        const double x = b.u(-30, 160), y = b.u(-40, 40);
        if (std::abs(y) < 3) continue;
        if (i % 3 == 0) {
          b.tree(x, y, b.s.groundHeight(x, y));
        } else {
          b.s.spheres.push_back({Eigen::Vector3d(x, y, b.s.groundHeight(x, y) + 0.4), b.u(0.4, 1.0)});
        }
      }
      break;
    }
    case SceneType::Square: {
      // An open paved square: a fountain, a few lamp posts, benches and kiosks; facades only
      // 55-75 m away, so most of the view is flat ground.
      b.ground();
      b.s.cylinders.push_back({b.u(30, 70), b.u(-25, 25), b.u(2, 4), -0.5, 0.6});
      for (int i = 0; i < 8; ++i) b.s.cylinders.push_back({b.u(-20, 130), b.u(-30, 30), 0.1, 0, b.u(4, 6)});
      for (int i = 0; i < 6; ++i) b.box(b.u(-20, 130), b.u(-30, 30), 0, b.u(1.5, 2), 0.6, 0.9);
      for (int i = 0; i < 3; ++i) b.box(b.u(-20, 130), b.u(-30, 30), 0, b.u(2, 4), b.u(2, 3), b.u(2.2, 3));
      for (int side : {-1, 1}) {
        for (double x = -80; x < 220;) {
          const double len = b.u(15, 40), depth = 15, h = b.u(8, 25);
          b.box(x + len / 2, side * (b.u(55, 75) + depth / 2), 0, len, depth, h);
          x += len + b.u(5, 30);
        }
      }
      break;
    }
    case SceneType::Slope: {
      // A 7 deg slope rising along x (3.4 deg across), rough: hundreds of bumps 5-40 cm high
      // and a few rocks, no upright surfaces but some boulders.
      b.ground(0.12, 0.06);
      for (int i = 0; i < 400; ++i) {
        const double x = b.u(-40, 170), y = b.u(-50, 50), r = b.u(0.8, 4.0);
        if (std::abs(y) < 1.5 + r) continue;  // keep the robot's track smooth
        b.bump(x, y, r, b.u(0.05, 0.4));
      }
      for (int i = 0; i < 40; ++i) {
        const double x = b.u(-40, 170), y = b.u(-50, 50), r = b.u(0.3, 1.5);
        if (std::abs(y) < 3 + r) continue;
        b.bump(x, y, r, r * b.u(0.8, 1.6));
      }
      break;
    }
    case SceneType::Forest: {
      // Dense vegetation on gently sloped ground: thin trunks 5-20 cm in radius, 3-12 m tall,
      // under no canopy the scanner sees, and bushes as clusters of small spheres. A 3 m trail
      // along x is free.
      b.ground(0.02, -0.03);
      for (int i = 0; i < 600; ++i) {
        const double x = b.u(-40, 170), y = b.u(-45, 45);
        if (std::abs(y) < 1.5) continue;
        const double z = b.s.groundHeight(x, y);
        b.s.cylinders.push_back({x, y, b.u(0.05, 0.2), z - 0.5, z + b.u(3, 12)});
      }
      for (int i = 0; i < 120; ++i) {
        const double x = b.u(-40, 170), y = b.u(-40, 40);
        if (std::abs(y) < 2.5) continue;
        const int parts = 3 + int(b.u(0, 5));
        for (int k = 0; k < parts; ++k) {
          const double px = x + b.u(-0.8, 0.8), py = y + b.u(-0.8, 0.8), r = b.u(0.2, 0.6);
          b.s.spheres.push_back({Eigen::Vector3d(px, py, b.s.groundHeight(px, py) + b.u(0, 0.8)), r});
        }
      }
      break;
    }
    case SceneType::Tunnel: {
      // A straight road tunnel, 11 m wide and 6 m high, 700 m long: within the scanner's 81 m
      // nothing fixes the position along x.
      b.ground();
      b.s.planes.push_back({Eigen::Vector3d(0, 0, -1), -6.0});  // ceiling at z = 6
      b.box(50, 6, 0, 700, 1, 6);
      b.box(50, -6, 0, 700, 1, 6);
      break;
    }
    case SceneType::Wall: {
      // A long wall 4-8 m high, its face 3-4 m left of the track, fills the left half of the
      // view; on the right an open field with a few trees and sheds 10-60 m away.
      b.ground();
      const double face = b.u(3.0, 4.0);
      b.box(60, face + 0.5, 0, 300, 1, b.u(4, 8));
      for (int i = 0; i < 15; ++i) {
        const double x = b.u(-30, 160), y = -b.u(10, 60);
        b.tree(x, y, 0);
      }
      for (int i = 0; i < 6; ++i) b.box(b.u(-30, 160), -b.u(10, 60), 0, b.u(2, 6), b.u(2, 6), b.u(2, 4));
      break;
    }
    case SceneType::Crowd: {
      // The street, with people walking on it (1.0-1.6 m/s, any heading) and cars driving
      // along it in two lanes (3-10 m/s): they move between two sweeps.
      b.street();
      for (int i = 0; i < 90; ++i) {
        Mover m;
        const double heading = b.u(-M_PI, M_PI), speed = b.u(1.0, 1.6);
        m.p0 = Eigen::Vector3d(b.u(-30, 150), b.u(-8.5, 8.5), 0.0);
        m.v = Eigen::Vector3d(speed * std::cos(heading), speed * std::sin(heading), 0.0);
        b.s.movers.push_back(m);
      }
      for (int i = 0; i < 30; ++i) {
        Mover m;
        m.car = true;
        const int lane = i % 2 ? 1 : -1;
        m.p0 = Eigen::Vector3d(b.u(-40, 160), lane * 2.6, 0.0);
        m.v = Eigen::Vector3d(-lane * b.u(3, 10), 0.0, 0.0);  // drive on the right
        b.s.movers.push_back(m);
      }
      break;
    }
  }
  return b.s;
}

}  // namespace cube_scan_matcher::sim
