#include "cube_scan_matcher/core/reference_grids.h"

#include <exception>

#include "cube_scan_matcher/core/parallel.h"

namespace cube_scan_matcher {

ReferenceGrids buildReferenceGrids(const PointArray& reference, const CubeGridSettings& grid,
                                   int fine_grids, double fine_edge_fraction, int threads,
                                   const PlaneMapSettings& planes) {
  ReferenceGrids r;
  rebuildReferenceGrids(r, reference, grid, fine_grids, fine_edge_fraction, threads, planes);
  return r;
}

void rebuildReferenceGrids(ReferenceGrids& r, const PointArray& reference,
                           const CubeGridSettings& grid, int fine_grids,
                           double fine_edge_fraction, int threads,
                           const PlaneMapSettings& planes) {
  // specs[0] is the E grid, the rest are the fine grids.
  std::vector<CubeGridSettings> specs{grid};
  CubeGridSettings gs = grid;
  gs.cube_edge *= fine_edge_fraction;
  for (int k = 0; k < fine_grids; ++k) {
    gs.origin_shift = double(k) / fine_grids;
    specs.push_back(gs);
  }
  r.fine.resize(specs.size() - 1);
  auto grid_of = [&r](std::size_t k) -> CubeGrid& { return k == 0 ? r.coarse : r.fine[k - 1]; };
  // The plane map, the longest job (as long as all grids on a corridor scan), goes first, so
  // that the other thread builds the grids meanwhile.
  const int first_grid = planes.enabled ? 1 : 0;
  const int jobs = int(specs.size()) + first_grid;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(jobs));
  runOnThreads(jobs, threads, [&](int k, int) {
    try {
      if (k < first_grid) {
        r.planes.rebuild(reference, planes.voxel, planes.min_points, planes.max_planarity,
                         planes.min_spread);
      } else {
        grid_of(std::size_t(k - first_grid)).rebuild(reference, specs[std::size_t(k - first_grid)]);
      }
    } catch (...) {
      errors[std::size_t(k)] = std::current_exception();
    }
  });
  if (!planes.enabled) r.planes = PlaneMap();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

GridWorkspace::GridWorkspace(const ReferenceGrids& grids) : coarse(grids.coarse) {
  retargetFine(grids);
  target_ = &grids;
}

void GridWorkspace::retarget(const ReferenceGrids& grids) {
  if (target_ == &grids) return;
  coarse.setGrid(grids.coarse);
  retargetFine(grids);
  target_ = &grids;
}

void GridWorkspace::setScan(const PointArray& coarse_points, const PointArray& fine_points) {
  coarse.setScan(coarse_points);
  for (CoincidenceObjective& j : fine) j.setScan(fine_points);
}

void GridWorkspace::retargetFine(const ReferenceGrids& grids) {
  if (fine.size() > grids.fine.size()) {
    fine.erase(fine.begin() + std::ptrdiff_t(grids.fine.size()), fine.end());
  }
  for (std::size_t k = 0; k < fine.size(); ++k) fine[k].setGrid(grids.fine[k]);
  for (std::size_t k = fine.size(); k < grids.fine.size(); ++k) fine.emplace_back(grids.fine[k]);
}

}  // namespace cube_scan_matcher
