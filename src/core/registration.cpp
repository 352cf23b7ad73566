#include "cube_scan_matcher/core/registration.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>
#include <stdexcept>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/voxel_collapse.h"

namespace cube_scan_matcher {

RegistrationSettings RegistrationSettings::paper(double cube_edge) {
  RegistrationSettings s;
  s.grid.cube_edge = cube_edge;
  s.gnmm = GnmmSettings{};
  s.collapse_fraction = 0.0;
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

/// Two poses within the search's agreement tolerances (translation norm, each angle).
bool samePose(const Vector6d& a, const Vector6d& b, const SearchSettings& ss) {
  const Vector6d d = a - b;
  return d.head<3>().norm() <= ss.consensus_translation &&
         d.tail<3>().cwiseAbs().maxCoeff() <= ss.consensus_rotation;
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
  }
  requireInRange("search starts", s.search.starts, 1, 64);
  requireInRange("search threads", s.search.threads, 1, 64);
  requireInRange("search consensus", s.search.consensus, 0, 64);
  if (!(s.search.consensus_translation > 0.0 && s.search.consensus_rotation > 0.0)) {
    throw std::invalid_argument("search consensus tolerances must be > 0");
  }
  requireInRange("search polish_runs", s.search.polish_runs, 0, 10);
  requireInRange("search polish_iterations", s.search.polish_iterations, 1, 1000000);
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

CubeRegistration::CubeRegistration(const RegistrationSettings& settings) : settings_(settings) {
  validate(settings_);
}

void CubeRegistration::setSettings(const RegistrationSettings& settings) {
  validate(settings);
  settings_ = settings;
}

void CubeRegistration::setReference(const PointArray& reference) {
  // Both grids are built before either is replaced, so an error keeps the previous reference.
  CubeGrid coarse = CubeGrid::build(reference, settings_.grid);
  std::vector<CubeGrid> fine;
  if (settings_.refine.enabled) {
    CubeGridSettings gs = settings_.grid;
    gs.cube_edge *= settings_.refine.edge_fraction;
    for (int k = 0; k < settings_.refine.grids; ++k) {
      gs.origin_shift = double(k) / settings_.refine.grids;
      fine.push_back(CubeGrid::build(reference, gs));
    }
  }
  grid_ = std::move(coarse);
  fine_grids_ = std::move(fine);
  has_reference_ = true;
}

const PointArray& CubeRegistration::prepareScan(const PointArray& scan, PointArray& storage,
                                               double fraction) const {
  if (fraction <= 0.0) return scan;
  storage = collapseToVoxels(scan, fraction * grid_.edge());
  return storage;
}

int CubeRegistration::score(const PointArray& scan, const Pose6& pose) const {
  if (!has_reference_) throw std::logic_error("CubeRegistration::score before setReference");
  if (scan.empty()) return 0;
  PointArray storage;
  CoincidenceObjective objective(grid_, prepareScan(scan, storage, settings_.collapse_fraction));
  return objective(pose);
}

GnmmResult CubeRegistration::coarseSearch(const PointArray& points, const Pose6& guess,
                                          CoincidenceObjective& objective,
                                          std::vector<Vector6d>* candidates) const {
  const SearchSettings& ss = settings_.search;
  // Independent starts (seeds seed + k) in rounds of `threads` starts, one per thread, each
  // thread with its own objective (its own working copy of V). After each round, stop once
  // `consensus` finished starts agree with the best one (the basin is found).
  const int threads = std::min(ss.threads, ss.starts);
  std::vector<std::unique_ptr<CoincidenceObjective>> objectives;
  for (int t = 1; t < threads; ++t) {
    objectives.push_back(std::make_unique<CoincidenceObjective>(grid_, points));
  }
  std::vector<GnmmResult> runs;
  runs.reserve(std::size_t(ss.starts));
  auto run = [&](int k, CoincidenceObjective& f, GnmmResult& out) {
    GnmmSettings gs = settings_.gnmm;
    gs.seed += std::uint64_t(k);
    out = Gnmm(gs).maximize([&f](const Vector6d& p) { return double(f(p)); }, guess);
  };
  while (int(runs.size()) < ss.starts) {
    const int first = int(runs.size()), count = std::min(threads, ss.starts - first);
    runs.resize(std::size_t(first + count));
    std::vector<std::thread> pool;
    for (int t = 1; t < count; ++t) {
      pool.emplace_back(run, first + t, std::ref(*objectives[std::size_t(t - 1)]),
                        std::ref(runs[std::size_t(first + t)]));
    }
    run(first, objective, runs[std::size_t(first)]);
    for (std::thread& t : pool) t.join();
    if (ss.consensus > 0) {
      const GnmmResult& top = *std::max_element(
          runs.begin(), runs.end(),
          [](const GnmmResult& a, const GnmmResult& b) { return a.best_value < b.best_value; });
      int agree = 0;
      for (const GnmmResult& r : runs) agree += samePose(r.best, top.best, ss);
      if (agree >= ss.consensus) break;
    }
  }

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
          [&](const Vector6d& c) { return samePose(runs[k].best, c, ss); });
      if (distinct) candidates->push_back(runs[k].best);
    }
  }
  GnmmResult best = std::move(runs[order.front()]);
  best.initial_value = runs[0].initial_value;

  // Polish: GNMM around the best pose so far with the bounds halved at each run.
  GnmmSettings gs = settings_.gnmm;
  gs.max_iterations = ss.polish_iterations;
  for (int run = 0; run < ss.polish_runs; ++run) {
    gs.bounds *= 0.5;
    gs.seed = settings_.gnmm.seed + std::uint64_t(ss.starts + run);
    const GnmmResult p = Gnmm(gs).maximize(
        [&objective](const Vector6d& x) { return double(objective(x)); }, best.best);
    evaluations += p.evaluations;
    iterations += p.iterations;
    restarts += p.restarts;
    if (p.best_value > best.best_value) {
      best.best = p.best;
      best.best_value = p.best_value;
    }
  }
  best.evaluations = evaluations;
  best.iterations = iterations;
  best.restarts = restarts;
  return best;
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
  if (!has_reference_) return finish(RegistrationStatus::NoReference, "no reference scan set");
  res.reference_cubes = grid_.occupiedCount();
  if (scan.empty()) return finish(RegistrationStatus::EmptyScan, "scan has no valid point");

  PointArray storage;
  const PointArray* points = &prepareScan(scan, storage, settings_.collapse_fraction);
  res.points_used = points->size();

  CoincidenceObjective objective(grid_, *points);
  std::vector<Vector6d> candidates;
  const GnmmResult g = coarseSearch(*points, guess, objective, &candidates);
  res.pose = g.best;
  res.J = res.J_coarse = int(g.best_value);
  res.J_guess = int(g.initial_value);
  res.evaluations = g.evaluations;
  res.iterations = g.iterations;
  res.restarts = g.restarts;
  res.stop = g.stop;

  // Refine stage (not in the paper): compass search on the fine grids from the coarse
  // result, maximising the sum of their J, on the scan collapsed at its own (finer) voxel; the
  // default, E/4, is half a fine cube.
  if (settings_.refine.enabled && res.J > 0 && !fine_grids_.empty()) {
    PointArray fine_storage;
    const PointArray& fine_points =
        settings_.refine.collapse_fraction == settings_.collapse_fraction
            ? *points
            : prepareScan(scan, fine_storage, settings_.refine.collapse_fraction);
    std::vector<CoincidenceObjective> fine;
    fine.reserve(fine_grids_.size());
    for (const CubeGrid& grid : fine_grids_) fine.emplace_back(grid, fine_points);
    // Multi-scale: the coarse cubes (weighted) join the fine grids' sum, so the refine stage
    // cannot trade coarse-level agreement for a fine-level near-tie.
    const double w = settings_.refine.coarse_weight;
    std::optional<CoincidenceObjective> coarse_on_fine;
    if (w > 0.0) coarse_on_fine.emplace(grid_, fine_points);
    auto fine_j = [&fine, &coarse_on_fine, w](const Vector6d& p) {
      int sum = 0;
      for (CoincidenceObjective& j : fine) sum += j(p);
      return double(sum) + (coarse_on_fine ? w * (*coarse_on_fine)(p) : 0.0);
    };
    // Refine the best `candidates` distinct coarse results (the winner first) and keep the
    // highest fine J: the finer cubes settle near-ties of the coarse J.
    candidates.resize(std::min(candidates.size(), std::size_t(settings_.refine.candidates)));
    if (candidates.empty()) candidates.push_back(res.pose);
    double best_fine = -1.0;
    for (const Vector6d& start : candidates) {
      const CompassResult c = compassMaximize(fine_j, start, settings_.refine.compass);
      res.evaluations += c.evaluations;
      if (c.best_value > best_fine) {
        best_fine = c.best_value;
        res.pose = c.best;
      }
    }
    res.J = objective(res.pose);
  }
  for (int k = 3; k < 6; ++k) res.pose[k] = wrapAngle(res.pose[k]);
  res.transform = poseToIsometry(res.pose);
  if (res.J == 0) {
    return finish(RegistrationStatus::NoOverlap,
                  "no scan point fell in a reference cube at any tried pose (no overlap)");
  }
  std::ostringstream os;
  os << "J = " << res.J << " of l = " << res.reference_cubes << " (J at guess " << res.J_guess
     << "), " << res.evaluations << " evaluations, stopped: " << toString(g.stop);
  return finish(RegistrationStatus::Ok, os.str());
}

}  // namespace cube_scan_matcher
