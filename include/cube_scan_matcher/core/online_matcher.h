// Online scan-to-keyframe registration with a pose chain: the ROS-free heart of the nodelet
// and of the sequence benchmark. Each scan (in the robot's base frame) is registered to the
// reference (the current keyframe, or a submap of the last keyframes merged into one cube grid
// in the keyframe's frame; the paper's "match multiple scans", section 5) around the odometry
// prediction, gated, and chained onto the keyframe's pose. An accepted scan that moved far
// enough from the keyframe becomes the next keyframe.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// When an accepted scan becomes the next keyframe: when it moved at least `distance` [m] or
/// `angle` [rad] from the current one, or `interval` [s] passed (0 = never by time). Zero
/// distance: every accepted scan is a keyframe (scan-to-scan chaining). A scan that did not
/// move far enough is registered to the same keyframe, so standing still adds no drift.
struct KeyframeSettings {
  double distance = 1.0;
  double angle = 10.0 * EIGEN_PI / 180.0;
  double interval = 0.0;
  /// Keyframes merged into the reference (1 = the last keyframe only), in [1, 20].
  int submap_size = 3;
};

/// De-skew with the corrected motion (core/deskew.h), for scans given with per-point times.
struct DeskewSettings {
  /// After the rigid registration found a pose (accepted by the gate or not), find the pose
  /// at which every line of the sweep lies on the reference when re-placed with the motion
  /// that pose implies (a continuous-time polish, plane_polish.h polishSweepOnPlanes),
  /// register the sweep re-placed there again, and keep the sweep re-placed with the final
  /// registered motion (instead of the odometry's, or none) as the keyframe. The gate's verdict
  /// on the first round's registration is the scan's: the rigid registration of a bent sweep
  /// is a compromise between its lines, often wrong where the gate cannot tell. Constant
  /// velocity since the last known scan; after rejected scans, the odometry's motion with its
  /// error since the known scan spread evenly (core/deskew.h SweepMotion). Only scans given
  /// with point times that differ (a sweep taken over time) are touched.
  bool enabled = true;
  /// Rounds: the first is the polish + a registration of the re-placed sweep (the verdict);
  /// each further round runs the continuous-time polish again from the result (no
  /// registration, unless the polish moves beyond the polish's max_shift_m / max_shift_rad:
  /// then the sweep re-placed there is registered again, kept if the gate accepts it). It
  /// stops once a round moves the result less than 1 mm and 0.01 deg. 0: the rigid
  /// registration's verdict, the sweep re-placed with its motion. In [0, 10].
  int iterations = 2;
  /// After rejected scans the sweep's own motion is not registered (the odometry's, or a
  /// constant velocity over the span), and a sweep still bent by it can be registered wrong
  /// where the gate accepts it. Its fit to the reference's planes shows the bend: the lines
  /// that do not fit leave the polish's kernel (fewer points on planes), those near it fit
  /// worse (a higher residual). Such a sweep is rejected (GateReason::BentSweep) when its
  /// registration's plane RMS exceeds max_rms_ratio times, or its fraction of points on
  /// planes (RegistrationResult::plane_correspondences / points_used) falls below
  /// min_plane_fraction_ratio times, the median of the last accepted results' (BENCHMARK.md,
  /// "Sweeps taken while driving"). Each 0 = off; else max_rms_ratio in [1, 100],
  /// min_plane_fraction_ratio in (0, 1].
  double max_rms_ratio = 1.6;
  double min_plane_fraction_ratio = 0.9;
};

/// The per-point times of a scan taken over time (a tilting scanner's sweep, a spinning
/// LiDAR's turn), for the de-skew.
struct PointTimes {
  std::vector<float> tau;  ///< [s] each point's time relative to the scan's stamp
  /// The points were placed in the base frame at the stamp with the odometry's motion (a cloud
  /// assembled in the odometry frame through tf); false: with none (a sweep in the sensor frame).
  bool placed_by_odometry = true;
};

struct OnlineMatcherSettings {
  RegistrationSettings registration;
  DeskewSettings deskew;
  GateSettings gate;
  KeyframeSettings keyframes;
  /// Without odometry, predict a scan from the last registered motion per second (constant
  /// velocity) instead of from no motion.
  bool constant_velocity = true;
  /// With constant_velocity and no odometry, also search from "no motion" (the last registered
  /// pose) and keep the higher J. Not used while no_odometry_grid is on (its grid is centred
  /// there).
  bool no_motion_candidate = true;
  /// J over all points peaks where the scan lies on the last scan's own sampling pattern, "no
  /// motion" (docs/method.md, the no-motion maximum). With odometry, a result there (within
  /// E/2 and 2 deg of the last known pose) that the gate rejects is searched again from the
  /// odometry's guess with the coarse stage on the densely sampled points alone
  /// (RegistrationSettings::dense_points = this), and that result is taken when the gate
  /// accepts it. Without odometry it is not used: there the no-motion candidate competes
  /// with the prediction, and measured in the park it turned rejections into wrong accepts.
  /// 0 = off; in [0, 1000].
  int no_motion_dense_points = 4;
  /// Without odometry the prediction is uncertain (the robot may start, stop or turn on the
  /// spot): the gate's correction bounds, and the search's restart bounds while
  /// no_odometry_grid is off, are multiplied by this (as by OnlineStep::gate_scale, the larger
  /// of the two). In [1, 10].
  double no_odometry_scale = 4.0;
  /// Without odometry, the search covers what a ground robot may have done since the last
  /// scan (driven on, stopped, turned on the spot; docs/method.md, "Without odometry: a planar
  /// grid search"): J on the coarse stage's densely sampled points over this planar grid
  /// around the last known pose (default +-2 m every 0.25 m, +-45 deg every 3 deg) seeds the
  /// GNMM starts 1.. (SearchSettings::grid), start 0 runs from the prediction within the
  /// unwidened restart bounds, and the no-motion candidate is not run. The correction is
  /// measured from the nearer of the prediction and "no motion", and the gate allows a
  /// rotation as wide as the grid's. After each rejected scan the yaw half width grows by its
  /// own value again (a turn goes on while its scans are missed), up to 180 deg. Off (both
  /// half widths 0): the prediction and the no-motion candidate in bounds widened by
  /// no_odometry_scale.
  PlanarGridSettings no_odometry_grid{2.0, 0.25, 0.7853981633974483, 0.05235987755982988};
  /// Without odometry and with no_odometry_grid: the coarse and the refine stages evaluate
  /// only the points of E-cubes holding at least this many (RegistrationSettings::dense_points
  /// and dense_refine), where J's maximum at "no motion" and at every submap keyframe's own
  /// pose is weakest. 0 = all points; in [0, 1000].
  int no_odometry_dense_points = 4;
  /// After this many consecutive rejected scans the step reports `rejection_alarm`. >= 1.
  int max_consecutive_rejections = 5;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const OnlineMatcherSettings& settings);

/// The work one online step did and where its wall time went: what a robot pays per scan
/// beyond a single registration (sequence_benchmark reports it per scan).
struct OnlineWork {
  int aligns = 0;       ///< Registration::align() calls: the scan, the no-motion candidate, de-skew rounds.
  int searches = 0;     ///< search attempts over those calls (RegistrationResult::attempts: 1 + retries used).
  int evaluations = 0;  ///< objective evaluations over those calls.
  int deskew_rounds = 0;        ///< de-skew rounds run (kept or not).
  bool reference_built = false;  ///< the submap's grids were rebuilt (a new keyframe).
  double register_s = 0.0;   ///< [s] the scan's registration from the guess.
  /// [s] The no-motion candidate's (no odometry) and the second search on the dense points of
  /// a rejected result at no motion (with odometry: no_motion_dense_points).
  double candidate_s = 0.0;
  double deskew_s = 0.0;     ///< [s] the de-skew rounds (sweep polish, re-placing, registration).
  double reference_s = 0.0;  ///< [s] the submap and its grids for a new keyframe.
  double total_s = 0.0;      ///< [s] the whole process() call.
  /// [s] Inside every align() call of the step (registration, candidate, de-skew rounds): the
  /// coarse GNMM search, the refine and the polish (RegistrationResult::time_*_s).
  double coarse_s = 0.0, refine_s = 0.0, polish_s = 0.0;
};

/// What happened to one scan.
struct OnlineStep {
  GateReason reason = GateReason::FirstScan;
  bool registered = false;         ///< align() ran (a reference existed and the scan had points).
  bool accepted = false;           ///< the registration result gave the increment.
  /// The guess came from odometry at both stamps (else the last known pose moved on at the
  /// last registered velocity, or not moved: OnlineMatcherSettings::constant_velocity).
  bool odometry_guess = false;
  bool reference_updated = false;  ///< this scan is now the keyframe (the reference rebuilt).
  bool time_reset = false;         ///< time went backwards: state was reset before this scan.
  bool rejection_alarm = false;    ///< consecutive rejections >= max_consecutive_rejections.
  bool deskewed = false;           ///< the points were re-placed with the registered motion.
  /// When deskewed: the scan's points re-placed (base frame at the stamp), one per input point
  /// in the same order; the keyframe holds the same.
  PointArray deskewed_points;
  int reregistered = 0;            ///< de-skew rounds whose result was kept (the step's result is the last one's).
  int consecutive_rejections = 0;
  /// The gate's max_correction bounds were multiplied by this: the time since the reference
  /// in whole scan periods (the lower quartile of the last 16 intervals), in [1, 4], and at
  /// least no_odometry_scale without odometry; the GNMM restart bounds are widened by the
  /// same factor for that registration. It is > 1 when scans were dropped or skipped: the
  /// odometry error grows with every increment the guess spans.
  double gate_scale = 1.0;
  RegistrationResult result;       ///< valid when registered.
  Pose6 guess = Pose6::Zero();     ///< scan -> reference guess [m, rad].
  Pose6 correction = Pose6::Zero();  ///< guess^-1 * result [m, rad] (zero if not registered).
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();  ///< scan -> keyframe, used.
  /// This scan's pose seen from the last scan whose pose was known (the first, an accepted or
  /// a forced one) and the time between them [s] (0 if first): the motion behind the twist.
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  double interval = 0.0;
  int keyframes = 0;               ///< keyframes in the reference after this scan.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();       ///< T_map_base of this scan.
  std::string message;             ///< why, for logs.
  OnlineWork work;                 ///< what this step cost.
};

class OnlineMatcher {
 public:
  explicit OnlineMatcher(const OnlineMatcherSettings& settings);  // validates

  /// `points`: the scan in the base frame at `stamp` [s] (finite points). `odom`: T_odom_base
  /// at `stamp` when known. The first scan's pose is its odometry pose (map = odom there), or
  /// identity without odometry. The guess is the odometry increment from the last reference
  /// whose pose is known, carried over the accepted poses since (without odometry: the last
  /// known pose moved on at the last registered velocity, or not moved if constant_velocity
  /// is off). A rejected scan never becomes a keyframe, unless
  /// max_consecutive_rejections scans in a row were rejected (the chain then moves on from the
  /// prediction). The gate's correction bounds and the search's restart bounds grow with the
  /// time the prediction spans, in whole scan periods: see OnlineStep::gate_scale.
  /// `times` (optional): each point's time relative to `stamp` and how the points were placed
  /// (PointTimes). With settings().deskew.enabled an accepted scan is re-placed with the
  /// registered motion (DeskewSettings), and the keyframe keeps the re-placed points.
  /// No NaN or infinite value enters the chain: odometry that is not a finite rigid motion is
  /// ignored (as if missing), and a step whose pose would not be one is refused
  /// (GateReason::NonFinite; the pose stays at the last known one). Throws
  /// std::invalid_argument if times->tau has the wrong size or `stamp` is not finite.
  OnlineStep process(const PointArray& points, double stamp,
                     const std::optional<Eigen::Isometry3d>& odom,
                     const PointTimes* times = nullptr);

  /// Forgets the reference, the pose chain and the rejection count.
  void reset();
  /// reset(), and the next scan starts the new chain at `pose` (T_map_base) instead of its
  /// odometry pose. Throws std::invalid_argument (and changes nothing) if `pose` is not a
  /// finite rigid motion.
  void restartAt(const Eigen::Isometry3d& pose);
  /// Takes effect at the next scan. Validates, and rebuilds the current reference's grids with
  /// the new settings at once: throws std::invalid_argument (and keeps the old settings) when
  /// they cannot be built, e.g. a cube edge whose grid exceeds the memory cap.
  void setSettings(const OnlineMatcherSettings& settings);
  const OnlineMatcherSettings& settings() const { return settings_; }
  bool hasReference() const { return registration_.hasReference(); }
  /// Heap bytes of the reference (the submap's grids and planes) and of the working copies
  /// (CubeRegistration), and of the keyframes' points kept for the submap.
  std::size_t referenceBytes() const { return registration_.referenceBytes(); }
  std::size_t workspaceBytes() const { return registration_.workspaceBytes(); }
  std::size_t keyframeBytes() const;
  /// Stamp of the last processed scan [s]; nullopt after reset.
  std::optional<double> lastStamp() const { return last_stamp_; }
  /// Pose of the last processed scan in the map frame.
  const Eigen::Isometry3d& lastPose() const { return last_pose_; }

 private:
  struct Keyframe {
    PointArray points;        // base frame
    Eigen::Isometry3d pose;   // T_map_base
    double stamp;             // [s]
  };
  /// The reference's points: the last submap_size keyframes in the frame of the newest, into
  /// `out` (its memory reused).
  static void submapPoints(const std::deque<Keyframe>& keyframes, int submap_size, PointArray& out);
  /// Adds a keyframe and rebuilds the reference; false (state unchanged) if its grid cannot
  /// be built, with the reason in `why`.
  bool addKeyframe(const PointArray& points, const Eigen::Isometry3d& pose, double stamp,
                   std::string& why);
  double gateScale(double stamp, double since) const;
  /// The gate's settings with the correction bounds multiplied by `gate_scale`.
  GateSettings scaledGate(double gate_scale) const;
  /// The predicted pose T_map_base and the stamp [s] of the pose it was predicted from.
  struct Prediction {
    Eigen::Isometry3d pose;
    double from;
  };
  // process()'s steps, in order.
  static std::optional<Eigen::Isometry3d> usableOdometry(const std::optional<Eigen::Isometry3d>& odom,
                                                        OnlineStep& step);
  void trackTime(double stamp, OnlineStep& step);
  Twist placedVelocity(double stamp, const std::optional<Eigen::Isometry3d>& odom,
                       const PointTimes* times);
  /// Also sets step.odometry_guess, step.increment and step.guess.
  Prediction predict(double stamp, const std::optional<Eigen::Isometry3d>& odom,
                     OnlineStep& step) const;
  /// Registers around the guess (and from no motion, without odometry), with the search and
  /// the gate widened by the scan periods the guess spans, and gates the result.
  void registerAndGate(OnlineStep& step, const PointArray& points, double stamp,
                       double predicted_from, const Keyframe& keyframe);
  /// "No motion": the last known pose, scan -> `keyframe` [m, rad]. Needs last_known_.
  Pose6 stillPose(const Keyframe& keyframe) const;
  /// With odometry, a rejected result at no motion searched again on the dense points
  /// (OnlineMatcherSettings::no_motion_dense_points) with `searched`, the settings of the first
  /// search; the result replaces step.result when the gate accepts it. True when it ran (the
  /// registration's settings are then not the defaults).
  bool searchDenseAtNoMotion(OnlineStep& step, const PointArray& points, const Keyframe& keyframe,
                             const RegistrationSettings& searched);
  /// Sets step.pose; false when the chain guard refused the step (not a finite rigid motion).
  bool placeScan(OnlineStep& step, const Keyframe* keyframe, const Eigen::Isometry3d& predicted);
  /// `keyframe`: the reference's frame (null for the first scan of a chain).
  void countRejections(OnlineStep& step, const Keyframe* keyframe);
  /// The known pose, the velocity, the keyframes and the anchor after this scan.
  void updateChain(OnlineStep& step, const PointArray& points, double stamp,
                   const std::optional<Eigen::Isometry3d>& odom, const Keyframe* keyframe,
                   bool refused);
  static void describe(OnlineStep& step);
  /// De-skews a scan whose rigid registration found a pose with the registered motion
  /// (`motion`: since last_known_) into `out` (DeskewSettings::iterations rounds): the first
  /// round's registration is the step's verdict (accepted or rejected). `out` is left empty
  /// when the step ends rejected.
  void deskewScan(OnlineStep& step, const PointArray& points, const PointTimes& times,
                  const SweepMotion& motion, const Twist& placed,
                  const GateSettings& gate_settings, bool after_rejection,
                  std::optional<PointArray>& out);
  OnlineMatcherSettings settings_;
  CubeRegistration registration_;
  std::deque<Keyframe> keyframes_;  // oldest first; back() is the reference's frame
  // Memory kept between keyframes (no fresh pages to fault in at each one): the merged submap,
  // and the points of the last keyframe to leave the submap, for the next one's copy.
  PointArray submap_, recycled_;
  std::optional<Eigen::Isometry3d> start_pose_;  // of the next first scan (restartAt)
  /// A scan whose pose is known: T_map_base, T_odom_base there (if it had odometry), stamp.
  struct Known {
    Eigen::Isometry3d pose;
    std::optional<Eigen::Isometry3d> odom;
    double stamp;
  };
  std::optional<Known> last_known_;  // the prediction without odometry starts here
  std::optional<Known> previous_odom_;  // the last scan with odometry (pose unused): the de-skew
  Pose6 velocity_ = Pose6::Zero();   // [m/s, rad/s] the last registered motion per second
  /// The last known scan that had odometry: a scan with odometry is predicted from it, also
  /// when the scans since then had none (a tf gap).
  std::optional<Known> anchor_;
  std::optional<double> last_stamp_;
  std::deque<double> intervals_;  // [s] between consecutive scans, the last kIntervals
  static constexpr std::size_t kIntervals = 16;
  /// The plane fit of a polished result: RMS [m] and fraction of its points on planes.
  struct PlaneFit {
    double rms, fraction;
    static PlaneFit of(const RegistrationResult& r) {
      return {r.plane_rms, double(r.plane_correspondences) / double(r.points_used)};
    }
  };
  std::deque<PlaneFit> recent_fits_;  // of the last kRecentFits accepted results
  static constexpr std::size_t kRecentFits = 9;
  /// Why a sweep registered after rejected scans is still bent (DeskewSettings::
  /// max_rms_ratio, min_plane_fraction_ratio), or empty when it is not.
  std::string bentSweep(const RegistrationResult& result) const;
  static constexpr double kMaxGateScale = 4.0;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  int consecutive_rejections_ = 0;
};

}  // namespace cube_scan_matcher
