// Beyond the paper: merge scan points that share a small voxel before the search. Points of one
// voxel of edge e << E almost always land in the same cube, so they add nothing to J but cost
// time in every evaluation; near the sensor a tilting scanner puts hundreds in one cube.
#pragma once

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher {

/// Keeps the first point of every voxel of edge `voxel` [m] (> 0), in input order (a scanner's
/// order is already spatially coherent). O(n) with an open-addressing hash.
PointArray collapseToVoxels(const PointArray& points, double voxel);

}  // namespace cube_scan_matcher
