// A 2D laser range-finder on a tilting mount, as the paper's (section 3.1, eq. 1): phi sweeps
// the 2D scan plane about Z, psi tilts it about X. In the sensor frame, a range r at (phi, psi)
// is the point [C(phi) r, C(psi) S(phi) r, S(psi) S(phi) r] (eq. 1), so phi = 90 deg, psi = 0
// looks along +Y. Defaults: phi over 180 deg in 0.5 deg steps, psi over 60 deg in 1/3 deg
// steps (361 x 181 = 65,341 beams), 81 m maximum range, +-4 cm range noise.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/sim/scene.h"

namespace cube_scan_matcher::sim {

struct ScannerModel {
  double phi_min_deg = 0.0, phi_max_deg = 180.0, phi_step_deg = 0.5;
  double psi_min_deg = -30.0, psi_max_deg = 30.0, psi_step_deg = 1.0 / 3.0;
  double max_range = 81.0;    ///< [m] beams beyond it (or with no return) give no point
  double range_noise = 0.04;  ///< [m] uniform +-noise added to every range
  /// Sensor artefacts (0 = off, the defaults): the probability that a beam gives no return,
  /// and that a beam at a range edge (a neighbour in its 2D scan more than mixed_pixel_edge
  /// [m] nearer or farther) returns a mixed pixel, a range uniform between the two surfaces.
  double dropout = 0.0;
  double mixed_pixels = 0.0;
  double mixed_pixel_edge = 0.3;
  int phiCount() const;       ///< beams per 2D scan (361 by default)
  int psiCount() const;       ///< 2D scans per sweep (181 by default)
};

/// Sensor-frame axes of eq. (1) relative to a REP-103 body (x forward, y left, z up): the
/// sensor's +Y (phi = 90 deg) looks along the body's +x, its +X along the body's -y.
Eigen::Matrix3d sensorToBodyRotation();

struct SweepOptions {
  /// true: one point per beam, NaN for no return (an organised cloud, as some drivers give);
  /// false: beams without a return are dropped.
  bool keep_invalid = false;
};

/// The paper's sensor with its artefacts on: 2 % dropouts, mixed pixels at half the edges.
ScannerModel scannerWithArtefacts();

/// Adds `count` no-return patches (Scene::no_return: dark or specular surfaces, puddles) of
/// 1-4 m radius, centred within x [-30, 160] m, |y| <= 30 m, z [-1, 4] m.
void addNoReturnPatches(Scene& scene, std::mt19937_64& rng, int count);

/// Casts every beam of one sweep from `sensor_pose` (sensor frame of eq. 1 -> world) and
/// returns the points in the sensor frame.
PointArray scan(const Scene& scene, const ScannerModel& model, const Eigen::Isometry3d& sensor_pose,
                std::mt19937_64& rng, const SweepOptions& options = {});

/// One 2D line at tilt `psi` [rad] cast from `sensor_pose` (eq. 1's frame -> world), in that
/// frame, one point per beam (phi ascending) with NaN for no return if keep_invalid: what a
/// driver's LaserScan holds, in eq. 1's frame turned by psi about its X axis (there the
/// beam at phi lies at [r cos(phi), r sin(phi), 0]).
PointArray scanLine(const Scene& scene, const ScannerModel& model, const Eigen::Isometry3d& sensor_pose,
                    double psi, std::mt19937_64& rng, bool keep_invalid = true);

/// A sweep taken while the scanner moves: the model's 2D lines evenly spaced in time
/// over [t_ref - duration, t_ref] (the reference time is the last line's), each cast from
/// `sensor_pose(t)` (T_world_sensor, eq. 1's frame) at its own time; tilt_up: the first line
/// at psi_min, else at psi_max (a tilting scanner sweeps up and down in turn). Beams within a
/// line are simultaneous (a 2D line takes ~1/75 s). The scene is the one given at every line.
struct TimedSweep {
  PointArray points;        ///< each in the sensor frame at its line's time
  std::vector<float> time;  ///< [s] line time - t_ref (in [-duration, 0]), one per point
};
TimedSweep scanDuringMotion(const Scene& scene, const ScannerModel& model,
                            const std::function<Eigen::Isometry3d(double)>& sensor_pose,
                            double t_ref, double duration, bool tilt_up, std::mt19937_64& rng,
                            const SweepOptions& options = {});

/// The sweep in the body frame at its reference time as tf would place it for a body moving
/// at constant velocity with `increment` (T_body(t_ref - interval)^-1 T_body(t_ref)) over
/// `interval` [s]: each point p (sensor frame at its time tau) goes to
/// exp(tau / interval * log(increment)) * mount * p (core/deskew.h).
PointArray placeSweep(const TimedSweep& sweep, const Eigen::Isometry3d& mount,
                      const Eigen::Isometry3d& increment, double interval);

/// One sweep from a robot at `body` (T_world_base) with the sensor mounted at the base's
/// origin (sensorToBodyRotation()), returned in the base frame (REP-103 axes).
PointArray scanInBody(const Scene& scene, const ScannerModel& model, const Eigen::Isometry3d& body,
                      std::mt19937_64& rng);

}  // namespace cube_scan_matcher::sim
