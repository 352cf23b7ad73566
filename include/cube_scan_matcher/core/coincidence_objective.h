// The integer objective J of the paper (section 2.1): the number of reference cubes that at
// least one scan point falls into, for a candidate pose. It knows nothing about the optimizer.
#pragma once

#include <cstdint>
#include <vector>

#include "cube_scan_matcher/core/cube_grid.h"
#include "cube_scan_matcher/core/point_array.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

class CoincidenceObjective {
 public:
  /// Keeps pointers to `grid` and `scan`: both must outlive the objective (or the next
  /// setScan()). All memory the evaluation needs is allocated here and in setScan(), none per
  /// evaluation.
  CoincidenceObjective(const CubeGrid& grid, const PointArray& scan);
  /// No scan yet: evaluate() gives 0 until setScan().
  explicit CoincidenceObjective(const CubeGrid& grid);

  /// Evaluates `scan` from now on, keeping the working copy of V (no reallocation of it).
  void setScan(const PointArray& scan);
  /// Evaluates on `grid` from now on. The working copy is reused, in O(l_old + l_new) steps
  /// plus any growth of it. The previous grid must still be alive during this call. Unbinds the scan: call setScan() before evaluating.
  void setGrid(const CubeGrid& grid);

  /// J for pose [x, y, z, roll, pitch, yaw] (eq. 2): transform every scan point, skip it if
  /// outside the grid, count each set cube once by clearing it in a working copy of V when
  /// hit, then restore the cleared cubes. O(n) and independent of E (section 2.2).
  int evaluate(const Pose6& pose);
  int operator()(const Pose6& pose) { return evaluate(pose); }

  /// J from cube indices computed elsewhere (MultiScaleObjective: several grids at one pose):
  /// startCount(), then countBlock() with the indices of every scan point on this grid
  /// (outsideIndex() for a point outside it), in blocks of at most kBlock, then finishCount(),
  /// which restores the working copy and returns J. evaluate() is these three.
  void startCount() { j_ = 0; }
  void countBlock(const std::int32_t* idx, std::size_t m);
  int finishCount();
  static constexpr std::size_t kBlock = 1024;  ///< points per index block (stays in L1)
  const CubeGrid& grid() const { return *grid_; }
  const PointArray* scan() const { return scan_; }
  std::int32_t outsideIndex() const { return outside_; }

  /// True if the working copy of V equals the grid's V (it must, between evaluations).
  bool workingCopyRestored() const;
  /// The working copy holds a byte per cube (else a bit per cube, as V).
  bool bytePerCube() const { return byte_mode_; }
  /// Heap bytes of the working copy of V and the index buffers.
  std::size_t memoryBytes() const {
    return bytes_.capacity() + bits_.capacity() * sizeof(std::uint64_t) +
           (hits_.capacity() + idx_.capacity()) * sizeof(std::int32_t);
  }

 private:
  void initWorkingCopy();  // from *grid_; byte copies must be all zero on entry
  /// Computes the cube indices of the scan block by block and hands each block to
  /// count_block(indices, m): the loop both counters share (inlined, no call per point).
  template <typename CountBlock>
  void forEachIndexBlock(const GridAffine& g, CountBlock&& count_block);
  void countBytes(const std::int32_t* idx, std::size_t m);  // one block, byte mode
  void countBits(const std::int32_t* idx, std::size_t m);   // one block, bit mode

  const CubeGrid* grid_;
  const PointArray* scan_ = nullptr;
  // The working copy of V with a spare always-zero cube past the grid, into which outside
  // points index: one byte per cube (grids up to max_byte_cubes) or one bit per cube. The
  // copy not in use is kept all zero (its memory serves the next grid of that mode).
  LargeBuffer<std::uint8_t> bytes_;
  LargeBuffer<std::uint64_t> bits_;
  bool byte_mode_ = false;
  std::vector<std::int32_t> hits_;  // bit mode: indices cleared in this evaluation (J of them)
  std::vector<std::int32_t> idx_;   // block of cube indices
  std::int32_t outside_ = 0;        // index of the spare zero cube
  int j_ = 0;                       // J so far in this evaluation
};

}  // namespace cube_scan_matcher
