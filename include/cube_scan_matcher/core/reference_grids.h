// The grids of one reference scan (the E grid of the coarse stage, the refine stage's fine
// grids and the polish's plane map) and one thread's working copies of them (GridWorkspace), which outlive a registration.
#pragma once

#include <vector>

#include "cube_scan_matcher/core/coincidence_objective.h"
#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/plane_map.h"
#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

struct ReferenceGrids {
  CubeGrid coarse;             ///< edge E: the coarse stage (and the refine's coarse term).
  std::vector<CubeGrid> fine;  ///< edge edge_fraction * E, origins shifted by k/grids.
  PlaneMap planes;             ///< the polish's local planes (empty when the polish is off).
  /// Heap bytes of all grids and the plane map.
  std::size_t memoryBytes() const {
    std::size_t bytes = coarse.memoryBytes() + planes.memoryBytes();
    for (const CubeGrid& g : fine) bytes += g.memoryBytes();
    return bytes;
  }
};

/// The plane map of a ReferenceGrids (see PlaneMap's constructor); none when not enabled.
struct PlaneMapSettings {
  bool enabled = false;
  double voxel = 0.25;  ///< [m]
  int min_points = 6;
  double max_planarity = 0.1;
  double min_spread = 0.0;  ///< fraction of the voxel (PlaneMap)
};

/// Builds the E grid (`grid`), `fine_grids` fine grids of edge fine_edge_fraction * E with
/// origins shifted by k/fine_grids of a fine cube and the plane map, on `threads` threads.
/// Throws the first CubeGridError (then nothing is returned).
ReferenceGrids buildReferenceGrids(const PointArray& reference, const CubeGridSettings& grid,
                                   int fine_grids, double fine_edge_fraction, int threads,
                                   const PlaneMapSettings& planes = PlaneMapSettings{});
/// The same into `grids`, reusing their memory (CubeGrid::rebuild, PlaneMap::rebuild): on a
/// virtual machine every fresh page costs a fault of some 10 us, and a Velodyne reference's
/// grids and plane map are ~2 MB. On error `grids` is left in a valid, unspecified state.
void rebuildReferenceGrids(ReferenceGrids& grids, const PointArray& reference,
                           const CubeGridSettings& grid, int fine_grids,
                           double fine_edge_fraction, int threads,
                           const PlaneMapSettings& planes = PlaneMapSettings{});

/// One thread's objectives: a working copy of every grid of a ReferenceGrids. Moving it to
/// other grids (retarget) reuses its memory instead of allocating it again.
class GridWorkspace {
 public:
  explicit GridWorkspace(const ReferenceGrids& grids);
  /// Moves every objective to `grids` (no-op when already on them). The previous grids must
  /// still be alive during this call. Unbinds the scans.
  void retarget(const ReferenceGrids& grids);
  /// Binds the E-grid objective to `coarse_points` and the fine ones to `fine_points`.
  void setScan(const PointArray& coarse_points, const PointArray& fine_points);

  CoincidenceObjective coarse;
  std::vector<CoincidenceObjective> fine;
  /// Heap bytes of the working copies.
  std::size_t memoryBytes() const {
    std::size_t bytes = coarse.memoryBytes();
    for (const CoincidenceObjective& o : fine) bytes += o.memoryBytes();
    return bytes;
  }

 private:
  void retargetFine(const ReferenceGrids& grids);
  const ReferenceGrids* target_ = nullptr;
};

}  // namespace cube_scan_matcher
