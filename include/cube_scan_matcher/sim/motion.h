// Simulated robot motion and DGPS/IMU odometry for the demo, the simulator node and tests:
// forward steps between sweeps like the paper's pairs, and odometry with known errors.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "cube_scan_matcher/sim/scene.h"

namespace cube_scan_matcher::sim {

struct MotionSettings {
  double step_min = 1.0, step_max = 5.0;  ///< [m] travel between sweeps.
  double yaw_change_max_deg = 45.0;       ///< [deg] largest heading change between sweeps.
  double heading_max_deg = 22.5;          ///< [deg] heading kept within this of the street axis.
  double lateral_limit = 2.0;             ///< [m] beyond |y| of this the robot turns back.
  double x_min = -10.0, x_max = 130.0;    ///< [m] U-turn (4 x 45 deg, 1 m steps) beyond these.
  double height = 1.0;                    ///< [m] base_link above the ground.
  double tilt_max_deg = 1.0;              ///< [deg] random roll and pitch.
};

/// Truth of base_link in the world (x forward along the street, z up), one pose per sweep.
class RobotMotion {
 public:
  RobotMotion(const Scene& scene, const MotionSettings& settings, std::uint64_t seed);
  const Eigen::Isometry3d& pose() const { return pose_; }
  /// Moves to the pose of the next sweep.
  void advance();

 private:
  void place();
  const Scene& scene_;
  MotionSettings s_;
  std::mt19937_64 rng_;
  double x_ = 0.0, y_ = 0.0, heading_ = 0.0;
  int dir_ = 1, turning_ = 0;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
};

/// T_world_base of a robot standing on the ground at (x, y) [m] with `heading` [rad]: base
/// `height` [m] above the ground, pitch and roll from the ground's slope over a 1 m footprint.
Eigen::Isometry3d placeOnGround(const Scene& scene, double x, double y, double heading, double height);

/// Continuous motion for sweeps taken while driving: constant speed along the
/// heading, and a yaw rate whose sign flips every `interval` (a zigzag about the heading
/// `heading0` the path starts from: the heading sweeps between heading0 -+ yaw_rate *
/// interval / 2, so the robot stays within speed / yaw_rate * (1 - cos(yaw_rate * interval
/// / 2)) [m] of the axis). On the ground (placeOnGround).
struct DrivenPathSettings {
  double speed = 1.0;          ///< [m/s]
  double yaw_rate_deg = 10.0;  ///< [deg/s]
  double interval = 2.0;       ///< [s] between flips of the yaw rate
  double height = 1.0;         ///< [m] base_link above the ground
};
class DrivenPath {
 public:
  DrivenPath(const Scene& scene, const DrivenPathSettings& settings, double x0, double y0, double heading0);
  /// T_world_base at time t >= 0 [s] (t = 0: (x0, y0), heading heading0 - yaw_rate*interval/2).
  Eigen::Isometry3d at(double t) const;

 private:
  const Scene& scene_;
  DrivenPathSettings s_;
  double x0_, y0_, h0_;
};

/// A transform with uniform errors within +-t [m] on x, y, z and +-a_deg [deg] on roll, pitch,
/// yaw (eq. 2): the odometry error of one increment.
Eigen::Isometry3d randomTransform(std::mt19937_64& rng, double t, double a_deg);

/// The motion between the two scans of the paper's Table 1 for a scene type (its ground truth
/// of the indoor, urban, park and natural pairs), as T_first_second in the simulator's body
/// frame (x forward, y left, z up). The paper's frame has X right, Y forward, Z up, and
/// [alpha, beta, gamma] about Z, Y, X composed as Rz(alpha) Ry(beta) Rx(gamma) (eq. 2); the
/// simulator's frame is the paper's turned by -90 deg about Z (M), so the motion is
/// M T_paper M^T: translation (y0, -x0, z0), yaw alpha, roll beta, pitch -gamma. Hall uses
/// the indoor row; the scene types beyond the paper's use the row of the nearest kind: tunnel
/// indoor, square, wall and crowd urban, forest park, slope natural.
Eigen::Isometry3d paperTable1Motion(SceneType type);

/// A random forward motion between two sweeps, T_first_second: travel uniform in [1, 5] m
/// along a heading halfway through the yaw change, yaw change uniform within +-45 deg,
/// height change within +-0.1 m, roll and pitch within +-2 deg.
Eigen::Isometry3d randomPairMotion(std::mt19937_64& rng);

enum class OdometryError {
  None,   ///< odometry = truth
  Small,  ///< each increment off by uniform +-0.25 m, +-2 deg per parameter (paper "small")
  Big,    ///< each increment off by uniform +-1 m, +-8 deg per parameter (paper "big")
  Drift,  ///< a slowly wandering offset (random walk, 5 cm and 0.3 deg per sweep): unbounded
  /// Globally referenced (DGPS/IMU): an offset from the truth in world axes that wanders but
  /// stays bounded (first-order Gauss-Markov, correlation time 20 sweeps; stationary sd 0.3 m
  /// per position axis, 0.2 deg roll and pitch, 0.5 deg yaw).
  Dgps,
};
/// "none", "small", "big", "drift", "dgps"; throws std::invalid_argument otherwise.
OdometryError odometryErrorFromString(const std::string& name);

/// T_odom_base per sweep. The first sweep's odometry equals the truth (map = odom = world).
class OdometrySimulator {
 public:
  OdometrySimulator(OdometryError mode, std::uint64_t seed);
  Eigen::Isometry3d next(const Eigen::Isometry3d& truth);

 private:
  OdometryError mode_;
  std::mt19937_64 rng_;
  bool first_ = true;
  Eigen::Isometry3d last_truth_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d last_odom_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d bias_ = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 1> offset_ = Eigen::Matrix<double, 6, 1>::Zero();  ///< Dgps [m, rad]
};

}  // namespace cube_scan_matcher::sim
