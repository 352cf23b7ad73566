// Scan registration by coincidence of coarse binary cubes, optimised with GNMM: the ROS-free
// front end. Settings in, result out; the grid of the reference is built once per reference.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "cube_scan_matcher/core/coarse_search.h"
#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/gnmm.h"
#include "cube_scan_matcher/core/plane_polish.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/core/pose.h"
#include "cube_scan_matcher/core/reference_grids.h"
#include "cube_scan_matcher/core/refine_search.h"

namespace cube_scan_matcher {

// The defaults of the settings structs are the package's shipped mode (beyond the paper; each
// choice measured in BENCHMARK.md): RegistrationSettings{} is what the tools, the nodelet and
// the README call "default", and RegistrationSettings::paper() is the paper's fixed mode.

/// Shipped mode: the coarse stage at E = 0.5 m on the scan collapsed to one point per E/2
/// voxel, four GNMM starts of 300 iterations (15 vertices, restarts within +-1 m/+-8 deg), two
/// at a time; the refine stage climbs the sum of J over three E/2 grids plus 3 x J on the E
/// grid from the two best distinct coarse results; the polish moves the refined pose to the
/// optimum of the point-to-plane distances to the reference's local planes and gives the
/// covariance. Working copies of grids up to 2^22 cubes use
/// a byte per cube.
struct RegistrationSettings {
  CubeGridSettings grid;  ///< E and the memory caps.
  GnmmSettings gnmm;      ///< population, iterations, restart bounds, seed.
  SearchSettings search;  ///< starts and threads of the coarse stage.
  RefineSettings refine;  ///< the fine stage (off in the paper's mode).
  PolishSettings polish;  ///< the point-to-plane polish and covariance (off in the paper's mode).
  /// Beyond the paper: before the search, keep one scan point per voxel of edge
  /// collapse_fraction * E. 0 = off, every point is evaluated (paper). In [0, 1]. E/2 is
  /// 1.1-1.35x faster on the real pairs than E/4 and as accurate on the scene benchmark, with
  /// the axis probe and the consensus rule catching the wall's slides (docs/experiments.md).
  double collapse_fraction = 0.5;
  /// Beyond the paper: the coarse search (and J_guess, J_coarse) uses only the scan points on
  /// densely sampled surfaces: those whose E-cube holds at least dense_points points of the
  /// scan (dense_sampling.h). Sparse far samples give J a false maximum at "no motion" (the scan
  /// laid where the reference was taken); the refine stage and the result's J use all points.
  /// 0 or 1 = off (every point, the paper); a scan with no such cube is used whole. In [0, 1000].
  /// Off by default for now: 4 cuts the drift of 150 m runs in the hall and park from 4-7 %
  /// to 0.2-0.6 %, but costs accuracy in some pairwise cases (docs/experiments.md, "The
  /// no-motion maximum and dense_points"); the drift benchmarks decide its default.
  int dense_points = 0;
  /// Beyond the paper: with dense_points, the refine stage evaluates the dense points as well
  /// (on its finer grids the sparse samples' maximum at "no motion" is sharper still, and it
  /// recurs wherever a keyframe of a merged submap was taken). Off: the refine uses all points.
  bool dense_refine = false;
  /// Beyond the paper: the coarse search evaluates at most this many of the collapsed points,
  /// evenly spaced in scan order (J at the result and the gate's J use them all). 0 = all.
  /// In [0, 1e7].
  int coarse_max_points = 0;
  /// Beyond the paper, off by default: each GNMM start of the coarse search screens first.
  /// Its iterations but the last screen_final_iterations evaluate J on every screen_stride-th
  /// coarse point (evenly spaced in scan order), then the population is evaluated on all
  /// points and the last iterations climb there: about (iterations - final) / stride + final
  /// full evaluations per start instead of iterations (300 iterations, stride 4, 50 final:
  /// 0.42x). It halves the coarse stage on the real sequence with the same drift, but costs
  /// successes in the open square and false accepts on the wall with the sensor's artefacts
  /// (docs/experiments.md, "Screening the coarse search"). Not used on scans with fewer than
  /// 500 x stride coarse points. 1 = off. In [1, 64] and [0, 1e6].
  int screen_stride = 1;
  int screen_final_iterations = 50;

  /// The paper's fixed mode: one GNMM of 15 vertices and 500 iterations on all points,
  /// restarts around the initial estimate within +-1 m / +-8 deg, no refine stage.
  static RegistrationSettings paper(double cube_edge = 0.5);
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const RegistrationSettings& settings);

enum class RegistrationStatus {
  Ok,           ///< J > 0 at the result.
  NoReference,  ///< align() before setReference().
  EmptyScan,    ///< the scan has no point.
  InvalidGuess,  ///< the initial estimate has a NaN or infinite parameter.
  NoOverlap,    ///< no scan point fell in a set cube at any evaluated pose (J = 0).
};
std::string toString(RegistrationStatus status);

struct RegistrationResult {
  RegistrationStatus status = RegistrationStatus::NoReference;
  Pose6 pose = Pose6::Zero();  ///< [m, m, m, rad, rad, rad]: scan -> reference (eq. 2).
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< same pose as a matrix.
  int J = 0;  ///< coincident cubes of edge E at the result (all points, collapsed as for coarse).
  int J_guess = 0;   ///< J at the initial estimate, on the coarse stage's points.
  std::size_t reference_cubes = 0;  ///< l: set cubes of the reference.
  std::size_t points_in = 0;      ///< scan points given.
  std::size_t points_used = 0;    ///< scan points evaluated (after collapsing).
  int evaluations = 0;             ///< objective evaluations, all stages.
  int iterations = 0;              ///< GNMM iterations, all runs.
  int restarts = 0;                ///< GNMM restarts, all runs.
  int J_coarse = 0;  ///< J at E after the first stage, on its points (dense_points filter).
  /// J at E before the polish (after the refine, on the result's points; 0 when the polish did
  /// not run). The polish moves the pose to the point-to-plane optimum, which can cost a few
  /// coincident cubes; a large loss means it left the cubes' maximum.
  int J_prepolish = 0;
  /// How far the polish moved the pose from the refine's result [m], [rad] (a diagnostic; 0
  /// when it did not run; PolishResult::shift_m).
  double polish_shift_m = 0.0, polish_shift_rad = 0.0;
  /// Search attempts run (the first, the retries: SearchSettings::retries) and the one the
  /// result comes from (0 = the first).
  int attempts = 1;
  int attempt_used = 0;
  /// Ambiguity: the coarse starts whose result lies within 0.25 m / 2 deg of the final pose,
  /// and the highest coarse J of the others (0 when every start agrees).
  int starts_agreeing = 0;
  int J_runner_up = 0;
  /// The best J of the probe along the weakest translation axis (SearchSettings::axis_probe_m;
  /// 0 when it did not run) and whether the result moved there (polished again from the probe).
  int J_axis = 0;
  bool axis_moved = false;
  /// SearchSettings::ambiguous_weak_ratio: the result was ambiguous and a retry landed on the
  /// same pose (consensus), or no retry did (ambiguous: the gate rejects it).
  bool consensus = false;
  bool ambiguous = false;
  double time_s = 0.0;            ///< wall time of align() [s].
  double time_coarse_s = 0.0;     ///< of which the coarse stage (the GNMM starts) [s].
  double time_refine_s = 0.0;     ///< of which the refine stage [s].
  double time_polish_s = 0.0;     ///< of which the polish and its covariance [s].
  /// The polish (plane_polish.h): whether it ran and moved the pose, its Gauss-Newton steps, the scan
  /// points near a reference plane at the result, their weighted RMS distance [m].
  bool polish_tried = false;  ///< the polish ran (enabled, and the reference has planes)
  bool polished = false;
  int polish_iterations = 0;
  int polish_points = 0;  ///< scan points the polish evaluated
  int plane_correspondences = 0;
  double plane_rms = 0.0;
  /// Covariance of the pose [x y z, small rotations about the reference frame's x y z]
  /// [m^2, rad^2] from the point-to-plane problem at the result; zero when the polish did not
  /// run or found too few planes.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  /// A direction with little information (a corridor's axis): see PolishResult.
  bool degenerate = false;
  Eigen::Matrix<double, 6, 1> weak_direction = Eigen::Matrix<double, 6, 1>::Zero();
  double weak_ratio = 0.0;
  Eigen::Vector3d translation_weak_axis = Eigen::Vector3d::Zero();
  double translation_weak_ratio = 0.0;
  int evaluations_refine = 0;     ///< of `evaluations`, those of the refine stage.
  /// Of `evaluations`, those of the planar grid (SearchSettings::grid; 0 when off); its time
  /// is in time_coarse_s.
  int evaluations_grid = 0;
  std::string message;            ///< human-readable summary or reason of failure.

  bool ok() const { return status == RegistrationStatus::Ok; }
  /// J / l: fraction of the reference cubes matched, in [0, 1].
  double overlap() const { return reference_cubes ? double(J) / double(reference_cubes) : 0.0; }
};

class CubeRegistration {
 public:
  explicit CubeRegistration(const RegistrationSettings& settings);  // validates
  ~CubeRegistration();
  /// Movable (a moved-from matcher may only be destroyed or assigned to), not copyable.
  CubeRegistration(CubeRegistration&&) noexcept;
  CubeRegistration& operator=(CubeRegistration&&) noexcept;
  CubeRegistration(const CubeRegistration&) = delete;
  CubeRegistration& operator=(const CubeRegistration&) = delete;

  /// Builds V and L of the reference (finite points; see filters.h). Throws CubeGridError;
  /// on error the previous reference is kept. Safe to call while another thread runs align():
  /// the grids are built aside and swapped in between two registrations.
  void setReference(const PointArray& reference);
  bool hasReference() const;
  /// The reference's E grid (an empty grid before setReference()). The reference is valid until
  /// the next setReference(): do not hold it across one running in another thread.
  const CubeGrid& grid() const;

  /// Registers `scan` to the reference around `guess` (scan -> reference). Calls on one
  /// instance are serialised (they share the per-thread working copies of the grids).
  RegistrationResult align(const PointArray& scan, const Pose6& guess) const;
  /// As align(scan, guess), with the planar grid (SearchSettings::grid) around `grid_centre`
  /// instead of around the guess (without odometry: the last known pose, "no motion").
  RegistrationResult align(const PointArray& scan, const Pose6& guess,
                           const Pose6& grid_centre) const;

  /// J of `scan` at `pose` on the coarse grid, with the same scan preparation as the result's
  /// J in align() (collapsing, all points). Needs a reference; returns 0 for an empty scan.
  int score(const PointArray& scan, const Pose6& pose) const;
  /// Heap bytes of the reference's grids and plane map (0 without a reference), including the
  /// previous reference's, kept as the memory the next one is built in; and of the threads'
  /// working copies of them.
  std::size_t referenceBytes() const;
  std::size_t workspaceBytes() const;
  /// polishSweepOnPlanes() on the reference's planes with the polish settings.
  /// Needs a reference with planes (else not applied, with the reason).
  SweepPolishResult polishSweep(const PointArray& scan, const std::vector<float>& tau,
                                const SweepMotion& motion, const Twist& placed, const Pose6& pose,
                                int max_iterations) const;

  const RegistrationSettings& settings() const { return settings_; }
  /// Takes effect at the next setReference()/align(); validates. A new cube_edge, max_cubes
  /// or refine grid setting needs a new setReference() (the grids are rebuilt only there).
  void setSettings(const RegistrationSettings& settings);

 private:
  struct ScanPoints;  // the points each stage evaluates

  /// Makes `count` workspaces on the current reference (reusing existing ones).
  void prepareWorkspaces(int count) const;
  /// The steps of align(), under the mutex.
  void prepareScan(const PointArray& scan, ScanPoints& points) const;
  /// Each thread's E-grid objective, bound to the coarse stage's points.
  std::vector<CoincidenceObjective*> coarseObjectives(const ScanPoints& points) const;
  /// The planar grid's best local maxima around `centre` (SearchSettings::grid): the seeds of
  /// starts 1.. of every attempt.
  std::vector<Pose6> gridStage(const ScanPoints& points, const Pose6& centre,
                               RegistrationResult& res) const;
  void coarseStage(const ScanPoints& points, const Pose6& guess,
                   const std::vector<Pose6>& seeds, int attempt, RegistrationResult& res,
                   std::vector<Pose6>& ranked, std::vector<int>& ranked_J) const;
  /// Compass search from the candidates; the index of the one the result started from.
  int refineStage(const ScanPoints& points, const std::vector<Pose6>& candidates,
                  RegistrationResult& res) const;
  void polishStage(const ScanPoints& points, RegistrationResult& res) const;
  /// The E grid's objective bound to all the scan's points, collapsed as for the coarse stage:
  /// J at a result, before and after the polish and along the axis probe.
  CoincidenceObjective& resultObjective(const ScanPoints& points) const;
  /// Probes J along the weakest translation axis of a polished result and moves it to a
  /// clearly higher J there (SearchSettings::axis_probe_m, axis_probe_gain).
  void axisProbeStage(const ScanPoints& points, RegistrationResult& res) const;
  /// Coarse, refine and polish stages from the seeds of `attempt` (0 = the first) into
  /// `ranked`/`ranked_J`; with `from` >= 0, no coarse stage: refine and polish from ranked[from]
  /// alone. Returns the index in `ranked` of the coarse result the refine's winner started from.
  int searchAttempt(const ScanPoints& points, const Pose6& guess, const std::vector<Pose6>& seeds,
                    int attempt, int from, RegistrationResult& res, std::vector<Pose6>& ranked,
                    std::vector<int>& ranked_J) const;
  /// Unbinds every objective from this call's points.
  void releaseScan() const;

  RegistrationSettings settings_;
  std::unique_ptr<ReferenceGrids> reference_;  // stable address: the workspaces point into it
  std::unique_ptr<ReferenceGrids> spare_;      // the previous reference: memory to rebuild into
  mutable std::vector<std::unique_ptr<GridWorkspace>> workspaces_;  // one per thread
  mutable std::unique_ptr<std::mutex> mutex_;  // serialises align() and score()
};

}  // namespace cube_scan_matcher
