// A long simulated run for the sequence benchmark: the robot drives up and down the scene's
// street one sweep at a time, stops now and then to stand still and to look around (a 90 deg
// turn on the spot and back), and turns round on the spot at the street's ends (or where an
// object blocks the way). It keeps clear of solids by its radius. Its pose
// follows the ground (height, and pitch and roll from the terrain's slope).
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Geometry>

#include "cube_scan_matcher/sim/scene.h"

namespace cube_scan_matcher::sim {

struct SequenceSettings {
  double step = 1.5;              ///< [m] travel per sweep while driving.
  double heading_jitter_deg = 3;  ///< [deg] largest random heading change per driving sweep.
  double heading_max_deg = 10;    ///< [deg] heading kept within this of the street axis.
  double turn_step_deg = 30;      ///< [deg] per sweep when turning on the spot.
  int drive_sweeps = 30;          ///< driving sweeps between stops.
  int stand_sweeps = 4;           ///< sweeps standing still at each stop (before the look-around).
  double lateral_limit = 1.5;     ///< [m] beyond |y| of this the robot steers back.
  double x_min = -5.0, x_max = 125.0;  ///< [m] turn round on the spot beyond these.
  double height = 1.0;            ///< [m] base_link above the ground.
  /// [m] the robot's radius: a driving sweep never ends closer than this to a solid (checked
  /// 0.2 m, 0.6 m and `height` above the ground). A step that would come closer turns up to 60 deg
  /// off its heading, else the robot turns round where it is.
  double clearance = 0.3;
};

class SequenceMotion {
 public:
  SequenceMotion(const Scene& scene, const SequenceSettings& settings, std::uint64_t seed);
  /// Truth of base_link in the world at the current sweep.
  const Eigen::Isometry3d& pose() const { return pose_; }
  /// Moves to the pose of the next sweep.
  void advance();

 private:
  enum class Phase { Drive, Stand, LookOut, LookBack, TurnRound };
  void place();
  /// Whether the robot fits at (x, y): no solid within `clearance` of its body.
  bool clear(double x, double y) const;
  const Scene& scene_;
  SequenceSettings s_;
  std::mt19937_64 rng_;
  double x_ = 0.0, y_ = 0.0, heading_ = 0.0, axis_ = 0.0;  // axis_: 0 or pi, the driving direction
  Phase phase_ = Phase::Drive;
  int left_ = 0;       // sweeps left in the phase
  double look_ = 1.0;  // side of the next look-around (+1 left, -1 right)
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
};

}  // namespace cube_scan_matcher::sim
