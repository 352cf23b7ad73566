// The integer objective J of the paper (section 2.1): the number of reference cubes that at
// least one scan point falls into, for a candidate pose. It knows nothing about the optimizer.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

class CoincidenceObjective {
 public:
  /// Keeps references to `grid` and `scan`: both must outlive the objective. All memory the
  /// evaluation needs is allocated here, none per evaluation.
  CoincidenceObjective(const CubeGrid& grid, const PointArray& scan);

  /// J for pose [x, y, z, roll, pitch, yaw] (eq. 2): transform every scan point, skip it if
  /// outside the grid, count each set cube once by clearing its bit in a working copy of V
  /// when hit, then restore the cleared bits. O(n) and independent of E (section 2.2).
  int evaluate(const Pose6& pose);
  int operator()(const Pose6& pose) { return evaluate(pose); }

  /// Number of evaluations so far.
  long evaluations() const { return evaluations_; }
  /// True if the working copy of V equals the grid's V (it must, between evaluations).
  bool workingCopyRestored() const {
    return std::equal(grid_.bits().begin(), grid_.bits().end(), work_.begin()) &&
           work_.back() == 0;
  }

 private:
  static constexpr std::size_t kBlock = 1024;  // points per index block (stays in L1)
  const CubeGrid& grid_;
  const PointArray& scan_;
  std::vector<std::uint64_t> work_;  // V, cleared on hit and restored after each evaluation
  std::vector<std::int32_t> hits_;   // indices cleared in this evaluation (J of them)
  std::vector<std::int32_t> idx_;    // block of cube indices
  std::int32_t outside_ = 0;         // index of the spare zero cube past V
  long evaluations_ = 0;
};

}  // namespace cube_scan_matcher
