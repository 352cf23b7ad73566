// Beyond the paper: the point-to-plane polish, the last stage of a registration. The cube
// stages find the basin (the coincidence count J is a step function: its maximum is a plateau
// of about a fine cube, so where the result lands on it depends on the start); a few
// Gauss-Newton steps on the distances of the scan points to the reference's local planes
// (plane_map.h) then move the pose to the continuous optimum inside that basin. The same
// least-squares problem gives the result's covariance and its weak directions.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/plane_map.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

struct PolishSettings {
  bool enabled = true;  ///< off in the paper's mode.
  /// Voxel of the plane map = voxel_fraction * E; a plane is fitted to the 3 x 3 x 3 voxels
  /// around a scan point's voxel. In (0, 2].
  double voxel_fraction = 0.5;
  int min_points = 6;           ///< reference points a plane needs, in [3, 1000].
  double max_planarity = 0.1;   ///< smallest / middle eigenvalue of a plane's points, (0, 1].
  /// A plane's points spread at least this fraction of the voxel along their second axis (a
  /// patch, not a scan column: PlaneMap). In [0, 1].
  double min_spread = 0.25;
  /// Geman-McClure kernel: a residual r [m] weighs (k^2 / (k^2 + r^2))^2; residuals beyond one
  /// voxel are no correspondence. k in (0, 1] m.
  double kernel = 0.05;
  int max_iterations = 20;  ///< Gauss-Newton steps in all, in [1, 100].
  /// Stop when a step moves less than these [m], [rad].
  double tolerance_m = 5e-4;
  double tolerance_rad = 1e-4;
  /// Over-relaxation: a step that keeps the previous step's direction (cosine > 0.8 in units
  /// where 1 rad = 1 m at the scan's radius of gyration) is taken 1.5 times as long as the
  /// previous one was stretched, up to this factor; any other step as computed. The robust
  /// weights make the plain steps fall short when the cube result is a few cm off (1-2 cm per
  /// step, 20 steps); the fixed point is the same. 1 = plain Gauss-Newton. In [1, 4].
  double max_overrelaxation = 2.0;
  /// Gauss-Newton steps per round of the polish: a round iterates on the scan points it
  /// collected near a plane at its start; with N > 0, after N steps without converging it
  /// collects them again where the pose is now (on one set for long, the steps can drift to
  /// where that set fits best as points leave their planes: an open square's 0.49 deg yaw
  /// drift, accepted 10.5 cm off). 8 removes that false accept; with max_shift_m 0.2 m it
  /// does not add another (docs/experiments.md, "The polish's rounds" and "A polish that must stay
  /// near the cube result"). 0 = a round ends only when it converges. In [0, 100].
  int round_steps = 8;
  /// The polish evaluates the scan collapsed to one point per voxel of this * E (the refine
  /// stage's points when equal to refine.collapse_fraction). 0 = all points. In [0, 2].
  double collapse_fraction = 0.5;
  /// The polish is discarded (the cube result kept, the result unconfirmed, so searched again)
  /// when it moves the pose more than max_shift_m or max_shift_rad from the cube result, or
  /// finds fewer than min_correspondences. 0.2 m (0.4 E): a
  /// polish that starts 0.2 m / 0.5 deg off after a poor refine walked 0.2497 m to a pose
  /// 11 cm off; right results move up to 0.24 m (robot worlds, p99 0.19 m), so this costs
  /// 13 of 5 900 accepted right results in the robot worlds and artefacts (docs/experiments.md,
  /// "A polish that must stay near the cube result").
  double max_shift_m = 0.2;
  double max_shift_rad = 0.03490658503988659;  // 2 deg
  int min_correspondences = 50;
  /// Directions whose information is below weak_ratio times the strongest one (in units where
  /// 1 rad = 1 m at the scan's radius of gyration) are not moved by the polish (numerically
  /// empty directions). In (0, 1).
  double weak_ratio = 1e-4;
  /// The result is flagged degenerate when its weakest direction's information is below
  /// degenerate_ratio times the strongest one's, or the weakest translation's supported
  /// information (the normals alone, sum w n n^T, see support_cosine) below
  /// translation_degenerate_ratio times the strongest translation's. In (0, 1).
  double degenerate_ratio = 1e-3;
  double translation_degenerate_ratio = 1e-2;
  /// [m] The standard deviation a degenerate translation axis gets at least (nothing in the
  /// scene fixes the pose along it). In [0, 1000].
  double degenerate_sigma_m = 1.0;
  /// The covariance: sigma^2 (H)^-1 from the weighted residuals, times this factor. The raw
  /// least-squares covariance is too small (neighbouring residuals share a reference plane's
  /// error): on the scene benchmark (20 worlds of each type, seed 1; docs/experiments.md,
  /// "A covariance from the residuals' clusters") the 99th
  /// percentile of |error| / sd per axis asked for factors of 1.6-12.5 (hall x the largest);
  /// 12 keeps every axis within 3 sd in ~99 % of the accepted results. In [1, 1e6].
  double covariance_scale = 12.0;
  /// Plus covariance_cell_scale times the clustered ("sandwich") covariance H^-1 B H^-1,
  /// B = sum over cubes c of edge covariance_cell_m [m] of g_c g_c^T, g_c the sum of the
  /// gradient terms w r J of the correspondences in c: model errors shared by a surface's
  /// points (tangent planes of trunks and poles met from another side) count once per cube,
  /// not once per point. The plain term alone left 46 % of the forest's accepted results
  /// beyond 3 sd along x (a 1 cm bias towards the motion) and 14-16 % of the square's; 2 m
  /// cubes and 25 bring every scene type of the robot worlds except the square to <= 1 %
  /// (docs/experiments.md, "A covariance from the residuals' clusters"). covariance_cell_m 0 = off;
  /// in [0, 100] m; scale in [0, 1e6].
  double covariance_cell_m = 2.0;
  double covariance_cell_scale = 25.0;
  /// > 1: each cube's share of the clustered term is the pose's change when the cube is left
  /// out, (H - H_c)^-1 g_c (a jackknife), instead of H^-1 g_c. Where a few cubes fix a
  /// direction (an open square's few small objects), the fit absorbs part of each one's error
  /// and its residual shows only (1 - leverage) of it; the jackknife restores it. H - H_c is
  /// replaced by H - (1 - 1/cap) H_c >= H / cap: a cube widens its share at most cap times in
  /// sd. 3 brings the square's yaw tail beyond 3 sd from 2.5 % to 1.3 % (docs/experiments.md, "A
  /// jackknife over the cubes"); <= 1 = off. In [0, 1e6].
  double covariance_jackknife_cap = 3.0;
  /// A correspondence carries information along a translation axis only when its plane's
  /// normal leans towards it by at least this cosine (0.15: 8.6 deg): the small random tilts
  /// of fitted normals are not information. In [0, 1).
  double support_cosine = 0.15;
};

/// Throws std::invalid_argument naming the bad setting (only when enabled).
void validate(const PolishSettings& settings);

struct PolishResult {
  bool applied = false;  ///< the polish moved the pose (else the input pose is returned).
  std::string reason;    ///< why not applied ("" when applied)
  Pose6 pose = Pose6::Zero();
  int iterations = 0;
  int correspondences = 0;  ///< scan points with a plane within one voxel at the result.
  /// How far the polish moved the pose from the cube result [m], [rad] (also when it is not
  /// applied because of max_shift_m / max_shift_rad; 0 when it found too few planes).
  double shift_m = 0.0, shift_rad = 0.0;
  double rms = 0.0;         ///< weighted RMS point-to-plane distance at the result [m].
  /// Covariance of [x y z, rotation about the reference frame's x y z] [m^2, rad^2]: small
  /// rotations applied on the left (R' = exp(dtheta) R, t' = t + dt), as ROS's
  /// PoseWithCovariance. Zero when no plane was found.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool degenerate = false;  ///< weak_ratio < settings.degenerate_ratio (a corridor's axis).
  /// The weakest direction, unit 6-vector in the same coordinates (rotations scaled by the
  /// radius of gyration), and its information relative to the strongest one.
  Eigen::Matrix<double, 6, 1> weak_direction = Eigen::Matrix<double, 6, 1>::Zero();
  double weak_ratio = 0.0;
  /// The same for translation alone: the weakest supported axis [unit 3-vector] and ratio.
  Eigen::Vector3d translation_weak_axis = Eigen::Vector3d::Zero();
  double translation_weak_ratio = 0.0;
};

/// Polishes `pose` (scan -> reference, eq. 2) on `map` with the points of `scan`. `threads`
/// share the passes over every scan point's plane lookups (and the lazy plane fits); the
/// result is the same for any number.
PolishResult polishOnPlanes(const PlaneMap& map, const PointArray& scan, const Pose6& pose,
                            const PolishSettings& settings, int threads = 1);

/// The continuous-time polish of a sweep taken while moving.
struct SweepPolishResult {
  bool applied = false;
  std::string reason;        ///< why not applied
  Pose6 pose = Pose6::Zero();
  int iterations = 0;
  int correspondences = 0;
  double shift_m = 0.0, shift_rad = 0.0;  ///< how far it moved the pose [m], [rad]
};

/// Polishes `pose` (scan -> reference, eq. 2) of a sweep whose points were placed with the
/// velocity `placed` (core/deskew.h; zero for a rigid sweep) and taken at times `tau` [s]
/// relative to the scan's stamp: every Gauss-Newton step re-places the points with the
/// velocity the pose implies (`motion`, core/deskew.h: since the last scan whose pose is
/// known, `motion.interval` [s] before the stamp), so that the result is the pose
/// at which every line of the sweep lies on the reference's planes, not a compromise between
/// the lines. At most max_iterations steps; stops at the settings' tolerances.
SweepPolishResult polishSweepOnPlanes(const PlaneMap& map, const PointArray& scan,
                                      const std::vector<float>& tau, const SweepMotion& motion,
                                      const Twist& placed, const Pose6& pose,
                                      const PolishSettings& settings, int max_iterations);

}  // namespace cube_scan_matcher
