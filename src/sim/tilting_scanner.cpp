#include "cube_scan_matcher/sim/tilting_scanner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher::sim {

int ScannerModel::phiCount() const {
  return int(std::floor((phi_max_deg - phi_min_deg) / phi_step_deg + 1e-6)) + 1;
}
int ScannerModel::psiCount() const {
  return int(std::floor((psi_max_deg - psi_min_deg) / psi_step_deg + 1e-6)) + 1;
}

Eigen::Matrix3d sensorToBodyRotation() {
  // Columns: sensor X, Y, Z in body coordinates. Sensor Y (phi = 90 deg) = body +x,
  // sensor X = body -y, sensor Z = body +z (right-handed: X x Y = Z).
  Eigen::Matrix3d r;
  r << 0, 1, 0,  //
      -1, 0, 0,  //
      0, 0, 1;
  return r;
}

namespace {

/// The primitives of `full` that a beam from `o` can reach within `reach` [m].
Scene cull(const Scene& full, const Eigen::Vector3d& o, double reach) {
  Scene scene;
  scene.planes = full.planes;
  scene.no_return = full.no_return;
  for (const Box& b : full.boxes) {
    const Eigen::Vector3d c = o.cwiseMax(b.lo).cwiseMin(b.hi);
    if ((c - o).norm() <= reach) scene.boxes.push_back(b);
  }
  for (const Cylinder& c : full.cylinders) {
    if (std::hypot(c.cx - o.x(), c.cy - o.y()) - c.r <= reach) scene.cylinders.push_back(c);
  }
  for (const Sphere& s : full.spheres) {
    if ((s.c - o).norm() - s.r <= reach) scene.spheres.push_back(s);
  }
  return scene;
}

/// Casts the 2D line at tilt `psi` [rad] from `pose` (sensor -> world) and appends its points
/// in the sensor frame to `out` (NaN for no return if keep_invalid). Returns the points added.
std::size_t castLine(const Scene& scene, const ScannerModel& m, const Eigen::Isometry3d& pose,
                     double psi, std::mt19937_64& rng, bool keep_invalid, PointArray& out) {
  std::uniform_real_distribution<double> noise(-m.range_noise, m.range_noise);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Eigen::Vector3d o = pose.translation();
  const Eigen::Matrix3d rot = pose.linear();
  const std::size_t before = out.size();
  std::vector<double> range(std::size_t(m.phiCount()));
  std::vector<Eigen::Vector3d> dirs(range.size());
  for (int i = 0; i < m.phiCount(); ++i) {
    const double phi = deg2rad(m.phi_min_deg + i * m.phi_step_deg);
    // Eq. (1) with r = 1: the beam direction in the sensor frame.
    dirs[i] = Eigen::Vector3d(std::cos(phi), std::cos(psi) * std::sin(phi), std::sin(psi) * std::sin(phi));
    range[i] = scene.raycast(o, rot * dirs[i], m.max_range);
  }
  for (int i = 0; i < m.phiCount(); ++i) {
    const double t = range[i];
    if (t <= 0.0 || (m.dropout > 0.0 && unit(rng) < m.dropout)) {
      if (keep_invalid) out.push_back(nan, nan, nan);
      continue;
    }
    double r = t + noise(rng);
    if (m.mixed_pixels > 0.0) {
      // The neighbour across the larger range jump, if it is an edge.
      double jump = 0.0;
      for (int k : {i - 1, i + 1}) {
        if (k < 0 || k >= m.phiCount() || range[k] <= 0.0) continue;
        if (std::abs(range[k] - t) > std::abs(jump)) jump = range[k] - t;
      }
      if (std::abs(jump) > m.mixed_pixel_edge && unit(rng) < m.mixed_pixels) r += unit(rng) * jump;
    }
    if (r > m.max_range || r <= 0.0) {
      if (keep_invalid) out.push_back(nan, nan, nan);
      continue;
    }
    const Eigen::Vector3f p = (dirs[i] * r).cast<float>();
    out.push_back(p.x(), p.y(), p.z());
  }
  return out.size() - before;
}

}  // namespace

PointArray scan(const Scene& full_scene, const ScannerModel& m, const Eigen::Isometry3d& pose,
                std::mt19937_64& rng, const SweepOptions& options) {
  // Cull primitives that no beam can reach.
  const Scene scene = cull(full_scene, pose.translation(), m.max_range + 1.0);
  PointArray out;
  out.reserve(std::size_t(m.phiCount()) * m.psiCount());
  for (int j = 0; j < m.psiCount(); ++j) {
    castLine(scene, m, pose, deg2rad(m.psi_min_deg + j * m.psi_step_deg), rng, options.keep_invalid, out);
  }
  return out;
}

PointArray scanLine(const Scene& full_scene, const ScannerModel& m, const Eigen::Isometry3d& pose,
                    double psi, std::mt19937_64& rng, bool keep_invalid) {
  PointArray out;
  castLine(cull(full_scene, pose.translation(), m.max_range + 1.0), m, pose, psi, rng, keep_invalid, out);
  return out;
}

TimedSweep scanDuringMotion(const Scene& full_scene, const ScannerModel& m,
                            const std::function<Eigen::Isometry3d(double)>& sensor_pose,
                            double t_ref, double duration, bool tilt_up, std::mt19937_64& rng,
                            const SweepOptions& options) {
  const int lines = m.psiCount();
  const double dt = lines > 1 ? duration / (lines - 1) : 0.0;
  std::vector<Eigen::Isometry3d> poses(static_cast<std::size_t>(lines));
  for (int k = 0; k < lines; ++k) poses[std::size_t(k)] = sensor_pose(t_ref - duration + k * dt);
  // Cull once around the middle line's origin, by the reach plus the path's extent.
  const Eigen::Vector3d mid = poses[std::size_t(lines / 2)].translation();
  double extent = 0.0;
  for (const Eigen::Isometry3d& p : poses) extent = std::max(extent, (p.translation() - mid).norm());
  const Scene scene = cull(full_scene, mid, m.max_range + 1.0 + extent);
  TimedSweep out;
  out.points.reserve(std::size_t(m.phiCount()) * std::size_t(lines));
  for (int k = 0; k < lines; ++k) {
    const int j = tilt_up ? k : lines - 1 - k;  // the tilt's line index
    const std::size_t n = castLine(scene, m, poses[std::size_t(k)],
                                   deg2rad(m.psi_min_deg + j * m.psi_step_deg), rng, options.keep_invalid, out.points);
    out.time.insert(out.time.end(), n, float(k * dt - duration));
  }
  return out;
}

PointArray placeSweep(const TimedSweep& sweep, const Eigen::Isometry3d& mount,
                      const Eigen::Isometry3d& increment, double interval) {
  const Twist xi = logMotion(increment);
  PointArray placed;
  placed.reserve(sweep.points.size());
  // One transform per line (points of a line share their time).
  std::size_t i = 0;
  while (i < sweep.points.size()) {
    std::size_t j = i;
    while (j < sweep.points.size() && sweep.time[j] == sweep.time[i]) ++j;
    const Eigen::Isometry3d to_ref = motionAt(xi, sweep.time[i], interval) * mount;
    for (std::size_t n = i; n < j; ++n) {
      const Eigen::Vector3d q = to_ref * sweep.points.point(n).cast<double>();
      placed.push_back(float(q.x()), float(q.y()), float(q.z()));
    }
    i = j;
  }
  return placed;
}

ScannerModel scannerWithArtefacts() {
  ScannerModel m;
  m.dropout = 0.02;
  m.mixed_pixels = 0.5;
  return m;
}

void addNoReturnPatches(Scene& scene, std::mt19937_64& rng, int count) {
  std::uniform_real_distribution<double> ux(-30.0, 160.0), uy(-30.0, 30.0), uz(-1.0, 4.0), ur(1.0, 4.0);
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3d c(ux(rng), uy(rng), uz(rng));
    scene.no_return.push_back({c, ur(rng)});
  }
}

PointArray scanInBody(const Scene& scene, const ScannerModel& model, const Eigen::Isometry3d& body,
                      std::mt19937_64& rng) {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sensorToBodyRotation();
  PointArray in_body;
  appendTransformed(in_body, scan(scene, model, body * mount, rng), mount);
  return in_body;
}

}  // namespace cube_scan_matcher::sim
