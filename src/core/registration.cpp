#include "cube_scan_matcher/core/registration.h"

#include <chrono>
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
    validate(s.refine.gnmm);
    if (s.refine.grids < 1 || s.refine.grids > 8) {
      throw std::invalid_argument("refine grids must be in [1, 8], got " +
                                  std::to_string(s.refine.grids));
    }
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
  const GnmmResult g = Gnmm(settings_.gnmm).maximize(
      [&objective](const Vector6d& p) { return double(objective(p)); }, guess);
  res.pose = g.best;
  res.J = res.J_coarse = int(g.best_value);
  res.J_guess = int(g.initial_value);
  res.evaluations = g.evaluations;
  res.iterations = g.iterations;
  res.restarts = g.restarts;
  res.stop = g.stop;

  // Refine stage (not in the paper): GNMM on the fine grids in a small box around the coarse
  // result, maximising the sum of their J. It evaluates the same (collapsed) points; the
  // default collapse voxel, E/4, is half a fine cube.
  if (settings_.refine.enabled && res.J > 0 && !fine_grids_.empty()) {
    std::vector<CoincidenceObjective> fine;
    fine.reserve(fine_grids_.size());
    for (const CubeGrid& grid : fine_grids_) fine.emplace_back(grid, *points);
    const GnmmResult f = Gnmm(settings_.refine.gnmm).maximize(
        [&fine](const Vector6d& p) {
          int sum = 0;
          for (CoincidenceObjective& j : fine) sum += j(p);
          return double(sum);
        },
        res.pose);
    res.pose = f.best;
    res.evaluations += f.evaluations;
    res.iterations += f.iterations;
    res.restarts += f.restarts;
    res.stop = f.stop;
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
