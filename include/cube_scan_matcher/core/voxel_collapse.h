// Beyond the paper: merge scan points that share a small voxel before the search. Points of one
// voxel of edge e << E almost always land in the same cube, so they add nothing to J but cost
// time in every evaluation; near the sensor a tilting scanner puts hundreds in one cube.
#pragma once

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

/// Keeps the first point of every voxel of edge `voxel` [m] (> 0), in input order (a scanner's
/// order is already spatially coherent). O(n) with an open-addressing hash.
PointArray collapseToVoxels(const PointArray& points, double voxel);

/// Whether every voxel of edge `fine` [m] lies inside one voxel of edge `coarse` [m] as
/// collapseToVoxels() cuts space (the coarse edge is the fine one times a power of two, exactly
/// in the float arithmetic of the keys). Then collapsing the fine result at `coarse` gives the
/// same points in the same order as collapsing the input at `coarse`, for points within
/// +-2^20 fine voxels of the origin (131 km at 0.125 m). False for an edge <= 0.
bool voxelsNest(double coarse, double fine);

}  // namespace cube_scan_matcher
