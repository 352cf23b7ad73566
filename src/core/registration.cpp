#include "cube_scan_matcher/core/registration.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <thread>
#include <sstream>
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

void validate(const RegistrationSettings& s) {
  validate(s.grid);
  validate(s.gnmm);
  if (s.refine.enabled) {
    if (!(s.refine.edge_fraction > 0.0 && s.refine.edge_fraction < 1.0)) {
      throw std::invalid_argument("refine edge_fraction must be in (0, 1), got " +
                                  std::to_string(s.refine.edge_fraction));
    }
    validate(s.refine.compass);
    if (s.refine.grids < 1 || s.refine.grids > 8) {
      throw std::invalid_argument("refine grids must be in [1, 8], got " +
                                  std::to_string(s.refine.grids));
    }
  }
  if (s.search.starts < 1 || s.search.starts > 64) {
    throw std::invalid_argument("search starts must be in [1, 64], got " +
                                std::to_string(s.search.starts));
  }
  if (s.search.threads < 1 || s.search.threads > 64) {
    throw std::invalid_argument("search threads must be in [1, 64], got " +
                                std::to_string(s.search.threads));
  }
  if (s.search.polish_runs < 0 || s.search.polish_runs > 10) {
    throw std::invalid_argument("search polish_runs must be in [0, 10], got " +
                                std::to_string(s.search.polish_runs));
  }
  if (s.search.polish_iterations < 1 || s.search.polish_iterations > 1000000) {
    throw std::invalid_argument("search polish_iterations must be in [1, 1000000], got " +
                                std::to_string(s.search.polish_iterations));
  }
  if (!(s.collapse_fraction >= 0.0 && s.collapse_fraction <= 1.0)) {
    throw std::invalid_argument("collapse_fraction must be in [0, 1], got " +
                                std::to_string(s.collapse_fraction));
  }
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

const PointArray& CubeRegistration::prepareScan(const PointArray& scan,
                                               PointArray& storage) const {
  if (settings_.collapse_fraction <= 0.0) return scan;
  storage = collapseToVoxels(scan, settings_.collapse_fraction * grid_.edge());
  return storage;
}

int CubeRegistration::score(const PointArray& scan, const Pose6& pose) const {
  if (!has_reference_) throw std::logic_error("CubeRegistration::score before setReference");
  if (scan.empty()) return 0;
  PointArray storage;
  CoincidenceObjective objective(grid_, prepareScan(scan, storage));
  return objective(pose);
}

GnmmResult CubeRegistration::coarseSearch(const PointArray& points, const Pose6& guess,
                                          CoincidenceObjective& objective) const {
  const SearchSettings& ss = settings_.search;
  // Independent starts (seeds seed + k) spread over threads: start k runs on thread
  // k % threads, each thread with its own objective (its own working copy of V).
  std::vector<GnmmResult> runs(std::size_t(ss.starts));
  auto run_starts = [&](int thread, CoincidenceObjective& f) {
    for (int k = thread; k < ss.starts; k += ss.threads) {
      GnmmSettings gs = settings_.gnmm;
      gs.seed += std::uint64_t(k);
      runs[std::size_t(k)] =
          Gnmm(gs).maximize([&f](const Vector6d& p) { return double(f(p)); }, guess);
    }
  };
  const int threads = std::min(ss.threads, ss.starts);
  std::vector<std::unique_ptr<CoincidenceObjective>> objectives;
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    objectives.push_back(std::make_unique<CoincidenceObjective>(grid_, points));
    pool.emplace_back(run_starts, t, std::ref(*objectives.back()));
  }
  run_starts(0, objective);
  for (std::thread& t : pool) t.join();

  int evaluations = 0, iterations = 0, restarts = 0;
  std::size_t winner = 0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    evaluations += runs[k].evaluations;
    iterations += runs[k].iterations;
    restarts += runs[k].restarts;
    if (runs[k].best_value > runs[winner].best_value) winner = k;
  }
  GnmmResult best = std::move(runs[winner]);
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
  const PointArray* points = &prepareScan(scan, storage);
  res.points_used = points->size();

  CoincidenceObjective objective(grid_, *points);
  const GnmmResult g = coarseSearch(*points, guess, objective);
  res.pose = g.best;
  res.J = res.J_coarse = int(g.best_value);
  res.J_guess = int(g.initial_value);
  res.evaluations = g.evaluations;
  res.iterations = g.iterations;
  res.restarts = g.restarts;
  res.stop = g.stop;

  // Refine stage (not in the paper): compass search on the fine grids from the coarse
  // result, maximising the sum of their J. It evaluates the same (collapsed) points; the
  // default collapse voxel, E/4, is half a fine cube.
  if (settings_.refine.enabled && res.J > 0 && !fine_grids_.empty()) {
    std::vector<CoincidenceObjective> fine;
    fine.reserve(fine_grids_.size());
    for (const CubeGrid& grid : fine_grids_) fine.emplace_back(grid, *points);
    const CompassResult c = compassMaximize(
        [&fine](const Vector6d& p) {
          int sum = 0;
          for (CoincidenceObjective& j : fine) sum += j(p);
          return double(sum);
        },
        res.pose, settings_.refine.compass);
    res.pose = c.best;
    res.evaluations += c.evaluations;
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
