#include "cube_scan_matcher/core/registration.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/dense_sampling.h"
#include "cube_scan_matcher/core/multi_scale_objective.h"
#include "cube_scan_matcher/core/voxel_collapse.h"
#include "require_in_range.h"

namespace cube_scan_matcher {

namespace {
/// A start agrees with the result when its coarse pose is this close [m], [rad].
constexpr double kAgreeTranslation = 0.25;
constexpr double kAgreeRotation = 0.03490658503988659;  // 2 deg
/// Two polished results of an ambiguous scan agree within these [m], [rad] (0.5 deg).
constexpr double kConsensusTranslation = 0.05;
constexpr double kConsensusRotation = 0.008726646259971648;

/// Starts whose coarse result lies near the final pose, and the best J of the others.
void countAgreement(const std::vector<Pose6>& ranked, const std::vector<int>& ranked_J,
                    RegistrationResult& res) {
  res.starts_agreeing = 0;
  res.J_runner_up = 0;
  for (std::size_t k = 0; k < ranked.size(); ++k) {
    if (posesWithin(ranked[k], res.pose, kAgreeTranslation, kAgreeRotation)) {
      ++res.starts_agreeing;
    } else {
      res.J_runner_up = std::max(res.J_runner_up, ranked_J[k]);
    }
  }
}

// The results in `ranked` that lie apart (kAgreeTranslation, kAgreeRotation) from `tried` and
// from each other: the one nearest to the prediction `guess` first (in units of the restart
// box `bounds`), then by decreasing J.
std::vector<int> untriedByPrediction(const std::vector<Pose6>& ranked, int tried,
                                     const Pose6& guess, const Vector6d& bounds) {
  std::vector<int> untried =
      distinctIndices(ranked, kAgreeTranslation, kAgreeRotation, int(ranked.size()), {tried});
  untried.erase(untried.begin());  // `tried` itself
  auto distance = [&](int k) {
    Pose6 d = ranked[std::size_t(k)] - guess;
    for (int i = 3; i < 6; ++i) d[i] = wrapAngle(d[i]);
    return d.cwiseAbs().cwiseQuotient(bounds).maxCoeff();
  };
  const auto nearest = std::min_element(untried.begin(), untried.end(),
                                        [&](int a, int b) { return distance(a) < distance(b); });
  if (nearest != untried.end()) std::rotate(untried.begin(), nearest, nearest + 1);
  return untried;
}

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

RegistrationSettings RegistrationSettings::paper(double cube_edge) {
  RegistrationSettings s;
  s.grid.cube_edge = cube_edge;
  s.gnmm.max_iterations = 500;
  s.search.starts = 1;
  s.search.threads = 1;
  s.search.axis_probe_m = 0.0;
  s.search.ambiguous_weak_ratio = 0.0;
  s.collapse_fraction = 0.0;
  s.dense_points = 0;
  s.refine.enabled = false;
  s.polish.enabled = false;
  return s;
}

void validate(const RegistrationSettings& s) {
  validate(s.grid);
  validate(s.gnmm);
  validate(s.refine);
  validate(s.search);
  validate(s.polish);
  requireInRange("collapse_fraction", s.collapse_fraction, 0.0, 1.0);
  requireInRange("dense_points", s.dense_points, 0, 1000);
  requireInRange("coarse_max_points", s.coarse_max_points, 0, 10000000);
  requireInRange("screen_stride", s.screen_stride, 1, 64);
  requireInRange("screen_final_iterations", s.screen_final_iterations, 0, 1000000);
}

std::string toString(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::Ok: return "ok";
    case RegistrationStatus::NoReference: return "no_reference";
    case RegistrationStatus::EmptyScan: return "empty_scan";
    case RegistrationStatus::InvalidGuess: return "invalid_guess";
    case RegistrationStatus::NoOverlap: return "no_overlap";
  }
  return "unknown";
}

// The points each stage evaluates: the scan itself or its collapsed copies (which the
// pointers may point into: not copyable).
struct CubeRegistration::ScanPoints {
  ScanPoints() = default;
  ScanPoints(const ScanPoints&) = delete;
  ScanPoints& operator=(const ScanPoints&) = delete;
  const PointArray* coarse = nullptr;  ///< the coarse search's points (dense part, collapsed)
  const PointArray* full = nullptr;    ///< all points collapsed as for the coarse search: J
  const PointArray* fine = nullptr;    ///< all points collapsed for the refine
  const PointArray* polish = nullptr;  ///< the polish's points (all points, collapsed)
  const PointArray* refine = nullptr;  ///< the refine's points (fine, or its dense part)
  const PointArray* screen = nullptr;  ///< the coarse points thinned for the screening iterations
  PointArray dense_storage, coarse_storage, full_storage, fine_storage, refine_storage,
      polish_storage, thinned_storage, screen_storage;
};

CubeRegistration::CubeRegistration(const RegistrationSettings& settings)
    : settings_(settings), mutex_(std::make_unique<std::mutex>()) {
  validate(settings_);
}

CubeRegistration::~CubeRegistration() = default;
CubeRegistration::CubeRegistration(CubeRegistration&&) noexcept = default;
CubeRegistration& CubeRegistration::operator=(CubeRegistration&&) noexcept = default;

void CubeRegistration::setSettings(const RegistrationSettings& settings) {
  validate(settings);
  std::lock_guard<std::mutex> lock(*mutex_);
  settings_ = settings;
}

bool CubeRegistration::hasReference() const {
  std::lock_guard<std::mutex> lock(*mutex_);
  return reference_ != nullptr;
}

const CubeGrid& CubeRegistration::grid() const {
  static const CubeGrid empty;
  return reference_ ? reference_->coarse : empty;
}

namespace {

/// Beyond the paper: the points of `cloud` on densely sampled surfaces (in `storage`), or
/// `cloud` itself when the filter is off or would keep nothing.
const PointArray* densePart(const PointArray& cloud, const RegistrationSettings& s, double edge,
                            PointArray& storage) {
  if (s.dense_points <= 1 || cloud.empty()) return &cloud;
  storage = keepDenselySampled(cloud, edge, s.dense_points);
  return storage.empty() ? &cloud : &storage;
}

}  // namespace

void CubeRegistration::setReference(const PointArray& reference) {
  // All grids are built (outside the lock, so a running align() is not held up) before any is
  // replaced, so an error keeps the previous reference.
  RegistrationSettings s;
  {
    std::lock_guard<std::mutex> lock(*mutex_);
    s = settings_;
  }
  PlaneMapSettings planes;
  planes.enabled = s.polish.enabled;
  planes.voxel = s.polish.voxel_fraction * s.grid.cube_edge;
  planes.min_points = s.polish.min_points;
  planes.max_planarity = s.polish.max_planarity;
  planes.min_spread = s.polish.min_spread;
  // The grids are rebuilt in the memory of the reference before the current one (the spare):
  // no fresh pages to fault in at every scan.
  std::unique_ptr<ReferenceGrids> next;
  {
    std::lock_guard<std::mutex> lock(*mutex_);
    next = std::move(spare_);
  }
  if (!next) next = std::make_unique<ReferenceGrids>();
  rebuildReferenceGrids(*next, reference, s.grid, s.refine.enabled ? s.refine.grids : 0,
                        s.refine.edge_fraction, s.search.threads, planes);
  std::lock_guard<std::mutex> lock(*mutex_);
  // The working copies move to the new grids while the old ones are still alive.
  for (auto& w : workspaces_) w->retarget(*next);
  spare_ = std::move(reference_);
  reference_ = std::move(next);
}

void CubeRegistration::prepareWorkspaces(int count) const {
  for (auto& w : workspaces_) w->retarget(*reference_);  // no-op when already on it
  while (int(workspaces_.size()) < count) {
    workspaces_.push_back(std::make_unique<GridWorkspace>(*reference_));
  }
}

namespace {

/// Beyond the paper: `scan` collapsed to one point per voxel of fraction * edge (in
/// `storage`), or `scan` itself for fraction 0.
const PointArray* collapsed(const PointArray& scan, double fraction, double edge,
                            PointArray& storage) {
  if (fraction <= 0.0) return &scan;
  storage = collapseToVoxels(scan, fraction * edge);
  return &storage;
}

}  // namespace

void CubeRegistration::prepareScan(const PointArray& scan, ScanPoints& p) const {
  const double edge = reference_->coarse.edge();
  const double cf = settings_.collapse_fraction, rf = settings_.refine.collapse_fraction;
  p.fine = collapsed(scan, rf, edge, p.fine_storage);
  // A coarser set is collapsed from a finer one whose voxels nest in its own (the same points
  // in the same order: the first of each voxel), which is a fraction of the points to hash.
  auto from = [&](const PointArray& all, double fraction) -> const PointArray& {
    return &all == &scan && rf > 0.0 && voxelsNest(fraction * edge, rf * edge) ? *p.fine : all;
  };
  const PointArray& dense = *densePart(scan, settings_, edge, p.dense_storage);
  p.coarse = cf == rf && &dense == &scan ? p.fine
                                         : collapsed(from(dense, cf), cf, edge, p.coarse_storage);
  p.full = &dense == &scan ? p.coarse
                           : collapsed(from(scan, cf), cf, edge, p.full_storage);
  p.refine = p.fine;
  if (settings_.dense_refine && &dense != &scan) p.refine = collapsed(dense, rf, edge, p.refine_storage);
  const std::size_t cap = std::size_t(settings_.coarse_max_points);
  if (cap > 0 && p.coarse->size() > cap) {
    // Evenly spaced in scan order: the sweep's lines keep their spread.
    const PointArray& all = *p.coarse;
    p.thinned_storage.reserve(cap);
    for (std::size_t i = 0; i < cap; ++i) {
      const std::size_t k = i * all.size() / cap;
      p.thinned_storage.push_back(all.x[k], all.y[k], all.z[k]);
    }
    p.coarse = &p.thinned_storage;
  }
  // Screening points for the coarse search (RegistrationSettings::screen_stride); not for a
  // scan so small that the subset leaves J too few cubes to tell poses apart.
  constexpr std::size_t kMinScreenPoints = 500;
  const std::size_t stride = std::size_t(settings_.screen_stride);
  if (stride > 1 && settings_.gnmm.max_iterations > settings_.screen_final_iterations &&
      p.coarse->size() / stride >= kMinScreenPoints) {
    const PointArray& all = *p.coarse;
    p.screen_storage.reserve((all.size() + stride - 1) / stride);
    for (std::size_t k = 0; k < all.size(); k += stride) {
      p.screen_storage.push_back(all.x[k], all.y[k], all.z[k]);
    }
    p.screen = &p.screen_storage;
  }
  if (!settings_.polish.enabled) return;
  const double pf = settings_.polish.collapse_fraction;
  p.polish = pf == rf   ? p.fine
             : pf == cf ? p.full
                        : collapsed(from(scan, pf), pf, edge, p.polish_storage);
}

void CubeRegistration::releaseScan() const {
  for (auto& w : workspaces_) w->setScan(PointArray::empty_array(), PointArray::empty_array());
}

std::size_t CubeRegistration::referenceBytes() const {
  std::lock_guard<std::mutex> lock(*mutex_);
  return (reference_ ? reference_->memoryBytes() : 0) + (spare_ ? spare_->memoryBytes() : 0);
}

std::size_t CubeRegistration::workspaceBytes() const {
  std::lock_guard<std::mutex> lock(*mutex_);
  std::size_t bytes = 0;
  for (const auto& w : workspaces_) bytes += w->memoryBytes();
  return bytes;
}

SweepPolishResult CubeRegistration::polishSweep(const PointArray& scan, const std::vector<float>& tau,
                                                const SweepMotion& motion, const Twist& placed,
                                                const Pose6& pose, int max_iterations) const {
  std::lock_guard<std::mutex> lock(*mutex_);
  if (!reference_) throw std::logic_error("CubeRegistration::polishSweep before setReference");
  return polishSweepOnPlanes(reference_->planes, scan, tau, motion, placed, pose,
                             settings_.polish, max_iterations);
}

int CubeRegistration::score(const PointArray& scan, const Pose6& pose) const {
  std::lock_guard<std::mutex> lock(*mutex_);
  if (!reference_) throw std::logic_error("CubeRegistration::score before setReference");
  if (scan.empty()) return 0;
  prepareWorkspaces(1);
  PointArray storage;
  CoincidenceObjective& objective = workspaces_[0]->coarse;
  objective.setScan(
      *collapsed(scan, settings_.collapse_fraction, reference_->coarse.edge(), storage));
  const int j = objective(pose);
  objective.setScan(PointArray::empty_array());
  return j;
}

std::vector<CoincidenceObjective*> CubeRegistration::coarseObjectives(
    const ScanPoints& points) const {
  std::vector<CoincidenceObjective*> objectives;
  for (auto& w : workspaces_) {
    w->coarse.setScan(*points.coarse);
    objectives.push_back(&w->coarse);
  }
  return objectives;
}

std::vector<Pose6> CubeRegistration::gridStage(const ScanPoints& points, const Pose6& centre,
                                               RegistrationResult& res) const {
  const SearchSettings& ss = settings_.search;
  if (!ss.grid.enabled() || ss.starts < 2) return {};
  const auto start = Clock::now();
  PlanarGridResult g =
      planarGridMaxima(coarseObjectives(points), ss.grid, centre, ss.starts - 1, ss.threads);
  res.evaluations_grid = g.evaluations;
  res.time_coarse_s += seconds(start, Clock::now());
  return std::move(g.maxima);
}

void CubeRegistration::coarseStage(const ScanPoints& points, const Pose6& guess,
                                   const std::vector<Pose6>& seeds, int attempt,
                                   RegistrationResult& res, std::vector<Pose6>& ranked,
                                   std::vector<int>& ranked_J) const {
  const std::vector<CoincidenceObjective*> objectives = coarseObjectives(points);
  GnmmSettings gnmm = settings_.gnmm;
  gnmm.seed += std::uint64_t(attempt) * std::uint64_t(settings_.search.starts);
  if (points.screen) {
    gnmm.screen_iterations = gnmm.max_iterations - settings_.screen_final_iterations;
  }
  const CoarseSearchResult c =
      coarseSearch(objectives, gnmm, settings_.search, guess, seeds, points.screen);
  res.pose = c.runs.front().best;
  res.J = res.J_coarse = int(c.runs.front().best_value);
  res.J_guess = c.J_guess;
  res.evaluations = c.evaluations;
  res.iterations = c.iterations;
  res.restarts = c.restarts;
  ranked.clear();
  ranked_J.clear();
  for (const GnmmResult& r : c.runs) {
    ranked.push_back(r.best);
    ranked_J.push_back(int(r.best_value));
  }
}

int CubeRegistration::refineStage(const ScanPoints& points,
                                  const std::vector<Pose6>& candidates,
                                  RegistrationResult& res) const {
  const RefineSettings& rs = settings_.refine;
  const Eigen::Vector3d pivot = centroid(*points.refine);
  std::vector<MultiScaleObjective> objectives;
  for (auto& w : workspaces_) {
    std::vector<CoincidenceObjective*> fine;
    for (CoincidenceObjective& j : w->fine) fine.push_back(&j);
    objectives.emplace_back(std::move(fine), &w->coarse, rs.coarse_weight, pivot);
  }
  // The refine's coarse term evaluates the refine's points on the E grid.
  for (auto& w : workspaces_) w->setScan(*points.refine, *points.refine);
  const RefineResult r =
      refineCandidates(objectives, candidates, rs.compass, settings_.search.threads);
  res.pose = r.pose;
  res.evaluations += r.evaluations;
  res.evaluations_refine = r.evaluations;
  return r.index;
}

void CubeRegistration::polishStage(const ScanPoints& points, RegistrationResult& res) const {
  const PolishResult p = polishOnPlanes(reference_->planes, *points.polish, res.pose,
                                        settings_.polish, settings_.search.threads);
  res.polish_tried = true;
  res.polished = p.applied;
  res.polish_iterations = p.iterations;
  res.polish_points = int(points.polish->size());
  res.plane_correspondences = p.correspondences;
  res.polish_shift_m = p.shift_m, res.polish_shift_rad = p.shift_rad;
  if (!p.applied) return;
  res.pose = p.pose;
  res.plane_rms = p.rms;
  res.covariance = p.covariance;
  res.degenerate = p.degenerate;
  res.weak_direction = p.weak_direction;
  res.weak_ratio = p.weak_ratio;
  res.translation_weak_axis = p.translation_weak_axis;
  res.translation_weak_ratio = p.translation_weak_ratio;
}

int CubeRegistration::searchAttempt(const ScanPoints& points, const Pose6& guess,
                                    const std::vector<Pose6>& seeds, int attempt, int from,
                                    RegistrationResult& res, std::vector<Pose6>& ranked,
                                    std::vector<int>& ranked_J) const {
  const RefineSettings& rs = settings_.refine;
  // Coarse search: GNMM starts on the E grid; or an earlier attempt's coarse result.
  const auto coarse_start = Clock::now();
  std::vector<int> refined;  // indices in `ranked` of the refine's candidates
  if (from >= 0) {
    res.pose = ranked[std::size_t(from)];
    res.J = res.J_coarse = ranked_J[std::size_t(from)];
    refined = {from};
  } else {
    coarseStage(points, guess, seeds, attempt, res, ranked, ranked_J);
    refined = distinctIndices(ranked, rs.distinct_translation, rs.distinct_rotation,
                              rs.candidates);
  }
  int refined_from = refined.front();
  const auto coarse_end = Clock::now();
  res.time_coarse_s = seconds(coarse_start, coarse_end);

  // Refine (not in the paper): compass search on the fine grids from the coarse results.
  if (rs.enabled && res.J > 0 && !reference_->fine.empty()) {
    std::vector<Pose6> candidates;
    for (const int k : refined) candidates.push_back(ranked[std::size_t(k)]);
    refined_from = refined[std::size_t(refineStage(points, candidates, res))];
    res.time_refine_s = seconds(coarse_end, Clock::now());
  }

  // Polish (not in the paper): point-to-plane Gauss-Newton from the cube result, and the
  // covariance.
  if (settings_.polish.enabled && res.J > 0 && reference_->planes.voxels() > 0) {
    const auto polish_start = Clock::now();
    // J on the E grid before the polish moves the pose (a diagnostic: how many coincident cubes
    // the point-to-plane optimum costs; a column of the scene benchmark's CSV).
    res.J_prepolish = resultObjective(points)(res.pose);
    ++res.evaluations;
    polishStage(points, res);
    res.time_polish_s = seconds(polish_start, Clock::now());
  }
  if (res.J > 0 && (rs.enabled || res.polished)) {
    res.J = resultObjective(points)(res.pose);
  }
  if (res.polished && !res.degenerate && settings_.search.axis_probe_m > 0.0) {
    const auto probe_start = Clock::now();
    axisProbeStage(points, res);
    res.time_polish_s += seconds(probe_start, Clock::now());
  }
  return refined_from;
}

CoincidenceObjective& CubeRegistration::resultObjective(const ScanPoints& points) const {
  CoincidenceObjective& objective = workspaces_[0]->coarse;
  objective.setScan(*points.full);
  return objective;
}

void CubeRegistration::axisProbeStage(const ScanPoints& points, RegistrationResult& res) const {
  const SearchSettings& ss = settings_.search;
  const double step = settings_.grid.cube_edge / 4.0;
  CoincidenceObjective& objective = resultObjective(points);
  Pose6 best_pose = res.pose;
  int best = res.J;
  for (double d = step; d <= ss.axis_probe_m + 1e-9; d += step) {
    for (const double sign : {-1.0, 1.0}) {
      Pose6 q = res.pose;
      q.head<3>() += sign * d * res.translation_weak_axis;
      const int j = objective(q);
      ++res.evaluations;
      if (j > best) best = j, best_pose = q;
    }
  }
  res.J_axis = best;
  if (double(best) <= double(res.J) * (1.0 + ss.axis_probe_gain)) return;
  // The search stopped short along the weak axis: polish again from the probe. (Not the
  // refine: its compass search climbs back towards the first result on the fine grids, and
  // the polish, weak along this axis by definition, then stays there.)
  RegistrationResult moved = res;
  moved.pose = best_pose;
  polishStage(points, moved);
  moved.J = objective(moved.pose);
  res.evaluations = ++moved.evaluations;
  if (moved.polished && moved.J > res.J) {
    moved.axis_moved = true;
    res = moved;
  }
}

RegistrationResult CubeRegistration::align(const PointArray& scan, const Pose6& guess) const {
  return align(scan, guess, guess);
}

RegistrationResult CubeRegistration::align(const PointArray& scan, const Pose6& guess,
                                           const Pose6& grid_centre) const {
  const auto start = Clock::now();
  RegistrationResult res;
  res.points_in = scan.size();
  res.pose = guess;
  res.transform = poseToIsometry(guess);
  auto finish = [&](RegistrationStatus status, const std::string& msg) {
    res.status = status;
    res.message = msg;
    res.time_s = seconds(start, Clock::now());
    return res;
  };
  // Everything below reads the reference and the workspaces: under the lock, so that a
  // concurrent setReference() waits instead of freeing the grids under this call.
  std::lock_guard<std::mutex> lock(*mutex_);
  if (!reference_) return finish(RegistrationStatus::NoReference, "no reference scan set");
  res.reference_cubes = reference_->coarse.occupiedCount();
  if (scan.empty()) return finish(RegistrationStatus::EmptyScan, "scan has no valid point");
  if (!guess.allFinite() || !grid_centre.allFinite()) {
    return finish(RegistrationStatus::InvalidGuess, "initial guess has a NaN or infinite value");
  }

  const SearchSettings& ss = settings_.search;
  const RefineSettings& rs = settings_.refine;
  prepareWorkspaces(std::max(std::min(ss.threads, ss.starts),
                             rs.enabled ? std::min(ss.threads, rs.candidates) : 1));

  // 1. The points each stage evaluates.
  ScanPoints points;
  prepareScan(scan, points);
  res.points_used = points.coarse->size();

  // 2-5. Coarse search, refine, polish, agreement; again from new seeds while the result is not
  // confirmed (SearchSettings::retries).
  const std::vector<Pose6> seeds = gridStage(points, grid_centre, res);
  const RegistrationResult before = res;
  double time_coarse = before.time_coarse_s, time_refine = 0.0, time_polish = 0.0;
  int evaluations = before.evaluations_grid, iterations = 0, restarts = 0, attempts = 0;
  bool done = false;                          // a confirmed result was taken
  std::optional<RegistrationResult> candidate;  // the best ambiguous result so far
  // With the planar grid the seeds are the same on every attempt, and a retry's coarse stage
  // lands on the same maxima. So a result that is not confirmed is retried first from the
  // first attempt's other coarse results, one at a time (untried: those apart from the ones
  // tried; a scan turned on the spot, where the coarse stage or the refine ranks the truth
  // below a submap keyframe's own pose), then by a new coarse search; an ambiguous result by a
  // new coarse search (a consensus needs an independent search).
  std::vector<Pose6> ranked0;
  std::vector<int> ranked0_J, untried;
  const bool from_ranked = ss.grid.enabled() && ss.retries > 0;
  int searches = 0;  // coarse searches run: at most 1 + retries
  bool previous_ambiguous = false;
  for (int attempt = 0;; ++attempt) {
    RegistrationResult r = before;
    std::vector<Pose6> r_ranked = ranked0;
    std::vector<int> r_ranked_J = ranked0_J;
    int from = -1;
    if (attempt > 0 && from_ranked && !previous_ambiguous && !untried.empty()) {
      from = untried.front();
      untried.erase(untried.begin());
    } else if (attempt > 0 && searches > ss.retries) {
      break;
    }
    if (from < 0) ++searches;
    const int refined_from =
        searchAttempt(points, guess, seeds, searches - 1, from, r, r_ranked, r_ranked_J);
    if (attempt == 0 && from_ranked) {
      ranked0 = r_ranked, ranked0_J = r_ranked_J;
      untried = untriedByPrediction(ranked0, refined_from, guess, settings_.gnmm.bounds);
    }
    ++attempts;
    time_coarse += r.time_coarse_s, time_refine += r.time_refine_s, time_polish += r.time_polish_s;
    evaluations += r.evaluations, iterations += r.iterations, restarts += r.restarts;
    r.attempt_used = attempt;
    // 5. Agreement of the starts with the result (ambiguity, for the acceptance gate).
    countAgreement(r_ranked, r_ranked_J, r);
    const bool confirmed = !r.polish_tried || (r.polished && !r.degenerate);
    const bool ambiguous = confirmed && r.polished &&
                           r.translation_weak_ratio < ss.ambiguous_weak_ratio &&
                           r.starts_agreeing <= ss.ambiguous_max_agreeing;
    if (attempt == 0) res = r;
    if (confirmed && !ambiguous) {
      res = r, done = true;
      break;
    }
    previous_ambiguous = ambiguous;
    if (!ambiguous) continue;
    if (candidate &&
        posesWithin(candidate->pose, r.pose, kConsensusTranslation, kConsensusRotation)) {
      res = r.J >= candidate->J ? r : *candidate;
      res.consensus = true, done = true;
      break;
    }
    if (!candidate || r.J > candidate->J) candidate = r;
  }
  if (!done && candidate) {
    res = *candidate;
    res.ambiguous = true;
  }
  res.attempts = attempts;
  res.time_coarse_s = time_coarse, res.time_refine_s = time_refine, res.time_polish_s = time_polish;
  res.evaluations = evaluations, res.iterations = iterations, res.restarts = restarts;

  // 6. Finish: no objective keeps a pointer to this call's points.
  releaseScan();
  for (int k = 3; k < 6; ++k) res.pose[k] = wrapAngle(res.pose[k]);
  res.transform = poseToIsometry(res.pose);
  if (res.J == 0) {
    return finish(RegistrationStatus::NoOverlap,
                  "no scan point fell in a reference cube at any tried pose (no overlap)");
  }
  std::ostringstream os;
  os << "J = " << res.J << " of l = " << res.reference_cubes << " (J at guess " << res.J_guess
     << "), " << res.evaluations << " evaluations";
  return finish(RegistrationStatus::Ok, os.str());
}

}  // namespace cube_scan_matcher
