#include "cube_scan_matcher/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace cube_scan_matcher::sim {

SceneType sceneTypeFromString(const std::string& name) {
  if (name == "hall") return SceneType::Hall;
  if (name == "urban") return SceneType::Urban;
  if (name == "park") return SceneType::Park;
  if (name == "natural") return SceneType::Natural;
  throw std::invalid_argument("unknown scene '" + name + "' (expected hall, urban, park or natural)");
}

std::string toString(SceneType type) {
  switch (type) {
    case SceneType::Hall: return "hall";
    case SceneType::Urban: return "urban";
    case SceneType::Park: return "park";
    case SceneType::Natural: return "natural";
  }
  return "unknown";
}

namespace {
constexpr double kNone = std::numeric_limits<double>::infinity();

double hitPlane(const Plane& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double den = p.n.dot(d);
  if (std::abs(den) < 1e-12) return kNone;
  const double t = (p.d - p.n.dot(o)) / den;
  return t > 1e-6 ? t : kNone;
}

double hitBox(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t0 = 1e-6, t1 = kNone;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (o[k] < b.lo[k] || o[k] > b.hi[k]) return kNone;
      continue;
    }
    double a = (b.lo[k] - o[k]) / d[k], c = (b.hi[k] - o[k]) / d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
    if (t0 > t1) return kNone;
  }
  return t0;
}

double hitCylinder(const Cylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double ox = o.x() - c.cx, oy = o.y() - c.cy;
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a < 1e-15) return kNone;
  const double b = ox * d.x() + oy * d.y();
  const double cc = ox * ox + oy * oy - c.r * c.r;
  const double disc = b * b - a * cc;
  if (disc < 0) return kNone;
  const double s = std::sqrt(disc);
  for (double t : {(-b - s) / a, (-b + s) / a}) {
    if (t <= 1e-6) continue;
    const double z = o.z() + t * d.z();
    if (z >= c.z0 && z <= c.z1) return t;
  }
  return kNone;
}

double hitSphere(const Sphere& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d oc = o - s.c;
  const double b = oc.dot(d);
  const double c = oc.squaredNorm() - s.r * s.r;
  const double disc = b * b - c;
  if (disc < 0) return kNone;
  const double q = std::sqrt(disc);
  if (-b - q > 1e-6) return -b - q;
  if (-b + q > 1e-6) return -b + q;
  return kNone;
}

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
    case SceneType::Urban: {
      // A street along x: building blocks with gaps on both sides, poles, parked cars, walls.
      b.ground();
      for (int side : {-1, 1}) {
        for (double x = -30; x < 160;) {
          const double len = b.u(8, 25), depth = b.u(8, 20), h = b.u(6, 25);
          const double y = side * (b.u(9, 13) + depth / 2);
          b.box(x + len / 2, y, 0, len, depth, h);
          x += len + b.u(2, 10);
        }
        for (double x = -25; x < 155; x += b.u(7, 12)) b.s.cylinders.push_back({x, side * b.u(6.5, 7.5), 0.12, 0, b.u(4, 8)});
        for (int i = 0; i < 14; ++i) b.box(b.u(-25, 150), side * b.u(4.5, 5.5), 0, b.u(3.8, 4.8), 1.8, b.u(1.3, 1.8));
      }
      for (int i = 0; i < 6; ++i) b.box(b.u(-20, 150), b.u(-8, 8), 0, b.u(0.3, 0.6), b.u(2, 6), b.u(0.8, 1.5));
      break;
    }
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
  }
  return b.s;
}

double Scene::groundHeight(double x, double y) const {
  double best = -kNone;
  for (const Plane& p : planes) {
    if (p.n.z() < 0.5) continue;  // not a floor
    const double z = (p.d - p.n.x() * x - p.n.y() * y) / p.n.z();
    best = std::max(best, z < 5.0 ? z : best);
  }
  return std::isfinite(best) ? best : 0.0;
}

double Scene::raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range) const {
  double t = kNone;
  for (const Plane& p : planes) t = std::min(t, hitPlane(p, o, d));
  for (const Box& b : boxes) t = std::min(t, hitBox(b, o, d));
  for (const Cylinder& c : cylinders) t = std::min(t, hitCylinder(c, o, d));
  for (const Sphere& s : spheres) t = std::min(t, hitSphere(s, o, d));
  return t <= max_range ? t : -1.0;
}

}  // namespace cube_scan_matcher::sim
