#include "cube_scan_matcher/core/registration.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <stdexcept>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/voxel_collapse.h"

namespace cube_scan_matcher {

RegistrationSettings RegistrationSettings::paper(double cube_edge) {
  RegistrationSettings s;
  s.grid.cube_edge = cube_edge;
  s.gnmm.max_iterations = 500;
  s.search.starts = 1;
  s.search.threads = 1;
  s.collapse_fraction = 0.0;
  s.refine.enabled = false;
  return s;
}

namespace {

/// Throws std::invalid_argument "<name> must be in [lo, hi], got <value>" (NaN fails too).
template <typename T>
void requireInRange(const char* name, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi)) {
    std::ostringstream os;
    os << name << " must be in [" << lo << ", " << hi << "], got " << value;
    throw std::invalid_argument(os.str());
  }
}

/// Two poses within the refine stage's distinct-candidate tolerances (translation norm, each
/// angle).
bool samePose(const Vector6d& a, const Vector6d& b, const RefineSettings& rs) {
  const Vector6d d = a - b;
  return d.head<3>().norm() <= rs.distinct_translation &&
         d.tail<3>().cwiseAbs().maxCoeff() <= rs.distinct_rotation;
}

}  // namespace

void validate(const RegistrationSettings& s) {
  validate(s.grid);
  validate(s.gnmm);
  if (s.refine.enabled) {
    if (!(s.refine.edge_fraction > 0.0 && s.refine.edge_fraction < 1.0)) {
      throw std::invalid_argument("refine edge_fraction must be in (0, 1), got " +
                                  std::to_string(s.refine.edge_fraction));
    }
    validate(s.refine.compass);
    requireInRange("refine coarse_weight", s.refine.coarse_weight, 0.0, 100.0);
    requireInRange("refine candidates", s.refine.candidates, 1, 64);
    requireInRange("refine grids", s.refine.grids, 1, 8);
    requireInRange("refine collapse_fraction", s.refine.collapse_fraction, 0.0, 1.0);
    if (!(s.refine.distinct_translation > 0.0 && s.refine.distinct_rotation > 0.0)) {
      throw std::invalid_argument("refine distinct_translation and distinct_rotation must be > 0");
    }
  }
  requireInRange("search starts", s.search.starts, 1, 64);
  requireInRange("search threads", s.search.threads, 1, 64);
  requireInRange("collapse_fraction", s.collapse_fraction, 0.0, 1.0);
}

std::string toString(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::Ok: return "ok";
    case RegistrationStatus::NoReference: return "no_reference";
    case RegistrationStatus::EmptyScan: return "empty_scan";
    case RegistrationStatus::NoOverlap: return "no_overlap";
  }
  return "unknown";
}

// The grids of one reference scan, built together in setReference().
struct CubeRegistration::Reference {
  CubeGrid grid;                   // edge E: the coarse stage (and the refine's coarse term)
  std::vector<CubeGrid> fine;      // edge edge_fraction * E, shifted: the refine stage
};

// One thread's objectives: a working copy of every grid, kept from one align() to the next
// (and retargeted, not reallocated, when the reference changes).
struct CubeRegistration::Workspace {
  explicit Workspace(const Reference& r) : coarse(r.grid) {
    retargetAll(fine, r.fine);
    target = &r;
  }

  // setReference() retargets every workspace before it frees the old reference, so `target`
  // is always the current reference or the one being installed.
  void retarget(const Reference& r) {
    if (target == &r) return;
    coarse.setGrid(r.grid);
    retargetAll(fine, r.fine);
    target = &r;
  }

  CoincidenceObjective coarse;
  std::vector<CoincidenceObjective> fine;
  const Reference* target = nullptr;

 private:
  static void retargetAll(std::vector<CoincidenceObjective>& objectives,
                          const std::vector<CubeGrid>& grids) {
    if (objectives.size() > grids.size()) {
      objectives.erase(objectives.begin() + std::ptrdiff_t(grids.size()), objectives.end());
    }
    for (std::size_t k = 0; k < objectives.size(); ++k) objectives[k].setGrid(grids[k]);
    for (std::size_t k = objectives.size(); k < grids.size(); ++k) {
      objectives.emplace_back(grids[k]);
    }
  }
};

namespace {

/// Runs job(k) for k = 0..count-1 on `threads` threads (the caller's thread is thread 0):
/// job k runs on thread k % threads, so thread t always uses workspace t.
template <typename Job>
void runOnThreads(int count, int threads, const Job& job) {
  threads = std::max(1, std::min(threads, count));
  auto worker = [&](int t) {
    for (int k = t; k < count; k += threads) job(k, t);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (std::thread& t : pool) t.join();
}

/// The centroid of the points [m] (double sums).
Eigen::Vector3d centroid(const PointArray& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) c += Eigen::Vector3d(p.x[i], p.y[i], p.z[i]);
  return p.empty() ? c : Eigen::Vector3d(c / double(p.size()));
}

}  // namespace

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

bool CubeRegistration::hasReference() const { return reference_ != nullptr; }

const CubeGrid& CubeRegistration::grid() const {
  static const CubeGrid empty;
  return reference_ ? reference_->grid : empty;
}

void CubeRegistration::setReference(const PointArray& reference) {
  // All grids are built before any is replaced, so an error keeps the previous reference.
  // The grid settings: the E grid, then the fine grids; built on the threads.
  std::vector<CubeGridSettings> specs{settings_.grid};
  if (settings_.refine.enabled) {
    CubeGridSettings gs = settings_.grid;
    gs.cube_edge *= settings_.refine.edge_fraction;
    for (int k = 0; k < settings_.refine.grids; ++k) {
      gs.origin_shift = double(k) / settings_.refine.grids;
      specs.push_back(gs);
    }
  }
  std::vector<CubeGrid> grids(specs.size());
  std::vector<std::exception_ptr> errors(specs.size());
  runOnThreads(int(specs.size()), settings_.search.threads, [&](int k, int) {
    try {
      grids[std::size_t(k)] = CubeGrid::build(reference, specs[std::size_t(k)]);
    } catch (...) {
      errors[std::size_t(k)] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  auto next = std::make_unique<Reference>();
  next->grid = std::move(grids[0]);
  for (std::size_t k = 1; k < specs.size(); ++k) next->fine.push_back(std::move(grids[k]));
  std::lock_guard<std::mutex> lock(*mutex_);
  // The working copies move to the new grids while the old ones are still alive.
  for (auto& w : workspaces_) w->retarget(*next);
  reference_ = std::move(next);
}

void CubeRegistration::prepareWorkspaces(int count) const {
  for (auto& w : workspaces_) w->retarget(*reference_);  // no-op when already on it
  while (int(workspaces_.size()) < count) {
    workspaces_.push_back(std::make_unique<Workspace>(*reference_));
  }
}

const PointArray& CubeRegistration::prepareScan(const PointArray& scan, PointArray& storage,
                                               double fraction) const {
  if (fraction <= 0.0) return scan;
  storage = collapseToVoxels(scan, fraction * reference_->grid.edge());
  return storage;
}

int CubeRegistration::score(const PointArray& scan, const Pose6& pose) const {
  if (!reference_) throw std::logic_error("CubeRegistration::score before setReference");
  if (scan.empty()) return 0;
  std::lock_guard<std::mutex> lock(*mutex_);
  prepareWorkspaces(1);
  PointArray storage;
  CoincidenceObjective& objective = workspaces_[0]->coarse;
  objective.setScan(prepareScan(scan, storage, settings_.collapse_fraction));
  const int j = objective(pose);
  objective.setScan(PointArray::empty_array());
  return j;
}

GnmmResult CubeRegistration::coarseSearch(const Pose6& guess,
                                          std::vector<Vector6d>* candidates) const {
  const SearchSettings& ss = settings_.search;
  // Independent starts (seeds seed + k), start k on thread k % threads, each on its thread's
  // working copy of V.
  std::vector<GnmmResult> runs(std::size_t(ss.starts));
  runOnThreads(ss.starts, ss.threads, [&](int k, int t) {
    CoincidenceObjective& f = workspaces_[std::size_t(t)]->coarse;
    GnmmSettings gs = settings_.gnmm;
    gs.seed += std::uint64_t(k);
    runs[std::size_t(k)] =
        Gnmm(gs).maximize([&f](const Vector6d& p) { return double(f(p)); }, guess);
  });

  int evaluations = 0, iterations = 0, restarts = 0;
  for (const GnmmResult& r : runs) {
    evaluations += r.evaluations;
    iterations += r.iterations;
    restarts += r.restarts;
  }
  // Starts by decreasing J (ties: lowest k first); the first is the winner, and the distinct
  // results in this order are the candidates of the refine stage.
  std::vector<std::size_t> order(runs.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return runs[a].best_value > runs[b].best_value;
  });
  if (candidates) {
    candidates->clear();
    for (std::size_t k : order) {
      const bool distinct = std::none_of(
          candidates->begin(), candidates->end(),
          [&](const Vector6d& c) { return samePose(runs[k].best, c, settings_.refine); });
      if (distinct) candidates->push_back(runs[k].best);
    }
  }
  GnmmResult best = std::move(runs[order.front()]);
  best.initial_value = runs[0].initial_value;
  best.evaluations = evaluations;
  best.iterations = iterations;
  best.restarts = restarts;
  return best;
}

void CubeRegistration::refine(const PointArray& points, std::vector<Vector6d> candidates,
                              RegistrationResult& res) const {
  const RefineSettings& rs = settings_.refine;
  // Multi-scale objective: the sum of J over the fine grids plus coarse_weight times J over
  // the E grids, so the refine stage cannot trade coarse-level agreement for a fine-level
  // near-tie.
  const double w = rs.coarse_weight;
  // Rotation pivot c: the refine variable is q = [R c + t, roll, pitch, yaw], so a rotation
  // step turns the points about c (pose: t = q_xyz - R c).
  const Eigen::Vector3d c = rs.centroid_pivot ? centroid(points) : Eigen::Vector3d::Zero();
  auto toPose = [&c](const Vector6d& q) {
    Pose6 p = q;
    p.head<3>() = q.head<3>() - poseToIsometry(q).linear() * c;
    return p;
  };
  auto toQ = [&c](const Pose6& p) {
    Vector6d q = p;
    q.head<3>() = poseToIsometry(p) * c;
    return q;
  };
  // The best `candidates` distinct coarse results (the winner first), one per thread; the
  // highest fine value wins (the finer cubes settle near-ties of the coarse J).
  candidates.resize(std::min(candidates.size(), std::size_t(rs.candidates)));
  if (candidates.empty()) candidates.push_back(res.pose);
  std::vector<CompassResult> results(candidates.size());
  runOnThreads(int(candidates.size()), settings_.search.threads, [&](int k, int t) {
    Workspace& ws = *workspaces_[std::size_t(t)];
    for (CoincidenceObjective& j : ws.fine) j.setScan(points);
    ws.coarse.setScan(points);
    auto value = [&ws, &toPose, w](const Vector6d& q) {
      const Pose6 p = toPose(q);
      int sum = 0, coarse_sum = 0;
      for (CoincidenceObjective& j : ws.fine) sum += j(p);
      if (w > 0.0) coarse_sum = ws.coarse(p);
      return double(sum) + w * double(coarse_sum);
    };
    results[std::size_t(k)] = compassMaximize(value, toQ(candidates[std::size_t(k)]), rs.compass);
  });
  double best = -1.0;
  for (const CompassResult& r : results) {
    res.evaluations += r.evaluations;
    res.evaluations_refine += r.evaluations;
    if (r.best_value > best) {
      best = r.best_value;
      res.pose = toPose(r.best);
    }
  }
}

RegistrationResult CubeRegistration::align(const PointArray& scan, const Pose6& guess) const {
  const auto start = std::chrono::steady_clock::now();
  RegistrationResult res;
  res.points_in = scan.size();
  res.pose = guess;
  res.transform = poseToIsometry(guess);
  auto finish = [&](RegistrationStatus status, const std::string& msg) {
    res.status = status;
    res.message = msg;
    res.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
  };
  if (!reference_) return finish(RegistrationStatus::NoReference, "no reference scan set");
  res.reference_cubes = reference_->grid.occupiedCount();
  if (scan.empty()) return finish(RegistrationStatus::EmptyScan, "scan has no valid point");

  std::lock_guard<std::mutex> lock(*mutex_);
  const SearchSettings& ss = settings_.search;
  const int threads = std::max(std::min(ss.threads, ss.starts),
                               settings_.refine.enabled
                                   ? std::min(ss.threads, settings_.refine.candidates)
                                   : 1);
  prepareWorkspaces(threads);

  PointArray storage;
  const PointArray* points = &prepareScan(scan, storage, settings_.collapse_fraction);
  res.points_used = points->size();
  for (auto& w : workspaces_) w->coarse.setScan(*points);

  std::vector<Vector6d> candidates;
  const auto coarse_start = std::chrono::steady_clock::now();
  const GnmmResult g = coarseSearch(guess, &candidates);
  const auto coarse_end = std::chrono::steady_clock::now();
  res.time_coarse_s = std::chrono::duration<double>(coarse_end - coarse_start).count();
  res.pose = g.best;
  res.J = res.J_coarse = int(g.best_value);
  res.J_guess = int(g.initial_value);
  res.evaluations = g.evaluations;
  res.iterations = g.iterations;
  res.restarts = g.restarts;

  // Refine stage (not in the paper): compass search on the fine grids from the coarse
  // results, on the scan collapsed at its own voxel; the default, E/4, is half a fine cube.
  if (settings_.refine.enabled && res.J > 0 && !reference_->fine.empty()) {
    PointArray fine_storage;
    const PointArray& fine_points =
        settings_.refine.collapse_fraction == settings_.collapse_fraction
            ? *points
            : prepareScan(scan, fine_storage, settings_.refine.collapse_fraction);
    refine(fine_points, std::move(candidates), res);
    CoincidenceObjective& objective = workspaces_[0]->coarse;
    objective.setScan(*points);
    res.J = objective(res.pose);
    res.time_refine_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - coarse_end).count();
  }
  // No objective keeps a pointer to this call's points.
  for (auto& w : workspaces_) {
    w->coarse.setScan(PointArray::empty_array());
    for (CoincidenceObjective& j : w->fine) j.setScan(PointArray::empty_array());
  }
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
