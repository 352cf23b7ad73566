#include "cube_scan_matcher/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace cube_scan_matcher::sim {

const std::vector<SceneType>& allSceneTypes() {
  static const std::vector<SceneType> all = {
      SceneType::Hall,   SceneType::Urban,  SceneType::Park, SceneType::Natural, SceneType::Square,
      SceneType::Slope,  SceneType::Forest, SceneType::Tunnel, SceneType::Wall,  SceneType::Crowd};
  return all;
}

std::string toString(SceneType type) {
  switch (type) {
    case SceneType::Hall: return "hall";
    case SceneType::Urban: return "urban";
    case SceneType::Park: return "park";
    case SceneType::Natural: return "natural";
    case SceneType::Square: return "square";
    case SceneType::Slope: return "slope";
    case SceneType::Forest: return "forest";
    case SceneType::Tunnel: return "tunnel";
    case SceneType::Wall: return "wall";
    case SceneType::Crowd: return "crowd";
  }
  return "unknown";
}

std::vector<std::string> expandSceneNames(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  const auto& types = allSceneTypes();
  for (const std::string& n : names) {
    if (n == "paper" || n == "robot" || n == "all") {
      const std::size_t from = n == "robot" ? kPaperSceneTypes : 0;
      const std::size_t to = n == "paper" ? kPaperSceneTypes : types.size();
      for (std::size_t k = from; k < to; ++k) out.push_back(toString(types[k]));
    } else {
      out.push_back(toString(sceneTypeFromString(n)));
    }
  }
  return out;
}

SceneType sceneTypeFromString(const std::string& name) {
  std::string known;
  for (const SceneType t : allSceneTypes()) {
    if (toString(t) == name) return t;
    known += (known.empty() ? "" : ", ") + toString(t);
  }
  throw std::invalid_argument("unknown scene '" + name + "' (expected one of " + known + ")");
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

}  // namespace

Scene Scene::at(double t) const {
  Scene out = *this;
  out.movers.clear();
  for (const Mover& m : movers) {
    const Eigen::Vector3d p = m.p0 + t * m.v;
    if (m.car) {
      out.boxes.push_back({p + Eigen::Vector3d(-2.25, -0.9, 0.0), p + Eigen::Vector3d(2.25, 0.9, 1.5)});
    } else {
      out.cylinders.push_back({p.x(), p.y(), 0.25, p.z(), p.z() + 1.7});
    }
  }
  return out;
}

bool Scene::insideSolid(const Eigen::Vector3d& p, double margin) const {
  for (const Box& b : boxes) {
    if ((p.array() >= b.lo.array() - margin).all() && (p.array() <= b.hi.array() + margin).all())
      return true;
  }
  for (const Cylinder& c : cylinders) {
    if (std::hypot(p.x() - c.cx, p.y() - c.cy) < c.r + margin && p.z() > c.z0 - margin &&
        p.z() < c.z1 + margin)
      return true;
  }
  for (const Sphere& s : spheres) {
    if ((p - s.c).norm() < s.r + margin) return true;
  }
  return false;
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
  if (t > max_range) return -1.0;
  if (!no_return.empty()) {
    const Eigen::Vector3d hit = o + t * d;
    for (const Sphere& s : no_return) {
      if ((hit - s.c).squaredNorm() < s.r * s.r) return -1.0;
    }
  }
  return t;
}

}  // namespace cube_scan_matcher::sim
