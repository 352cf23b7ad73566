// The reference's grids and the per-thread working copies that outlive a reference.
#include <gtest/gtest.h>

#include "cube_scan_matcher/core/reference_grids.h"
#include "grid_test_helpers.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::test;

TEST(ReferenceGrids, TheEGridAndTheShiftedFineGrids) {
  const PointArray ref = cornerScene(3000, 5);
  const ReferenceGrids g = buildReferenceGrids(ref, edge(0.5), 3, 0.5, 2);
  EXPECT_DOUBLE_EQ(g.coarse.edge(), 0.5);
  ASSERT_EQ(g.fine.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(g.fine[std::size_t(k)].edge(), 0.25);
    // Origin shifted by k/3 of a fine cube (eq. 6 with min - shift * edge).
    EXPECT_NEAR(g.fine[std::size_t(k)].minCorner().x(),
                g.fine[0].minCorner().x() - k / 3.0 * 0.25, 1e-9);
  }
  EXPECT_TRUE(buildReferenceGrids(ref, edge(0.5), 0, 0.5, 2).fine.empty());
}

TEST(ReferenceGrids, AnErrorInAnyGridIsThrown) {
  PointArray ref = cornerScene(100, 6);
  ref.push_back(1e6f, 1e6f, 1e6f);  // absurd extent
  EXPECT_THROW(buildReferenceGrids(ref, edge(0.5), 3, 0.5, 2), CubeGridError);
}

TEST(ReferenceGrids, RebuiltInTheMemoryOfOthersTheyEqualFreshOnes) {
  const PointArray small = cornerScene(3000, 11), big = cornerScene(20000, 12);
  PlaneMapSettings planes;
  planes.enabled = true;
  const ReferenceGrids fresh = buildReferenceGrids(small, edge(0.5), 3, 0.5, 2, planes);
  // Into the grids of a larger scan, with other settings, and after an error.
  ReferenceGrids reused = buildReferenceGrids(big, edge(0.4), 2, 0.5, 2, planes);
  PointArray absurd = small;
  absurd.push_back(1e6f, 1e6f, 1e6f);
  EXPECT_THROW(rebuildReferenceGrids(reused, absurd, edge(0.5), 3, 0.5, 2, planes), CubeGridError);
  rebuildReferenceGrids(reused, small, edge(0.5), 3, 0.5, 2, planes);
  ASSERT_EQ(reused.fine.size(), 3u);
  for (std::size_t k = 0; k < 4; ++k) {
    const CubeGrid& a = k == 0 ? fresh.coarse : fresh.fine[k - 1];
    const CubeGrid& b = k == 0 ? reused.coarse : reused.fine[k - 1];
    EXPECT_EQ(a.dims(), b.dims()) << k;
    EXPECT_EQ(a.minCorner(), b.minCorner()) << k;
    EXPECT_EQ(a.bits(), b.bits()) << k;
    EXPECT_EQ(a.list(), b.list()) << k;
  }
  ASSERT_EQ(fresh.planes.voxels(), reused.planes.voxels());
  ASSERT_GT(fresh.planes.voxels(), 0u);
  int planes_found = 0;
  for (std::size_t i = 0; i < small.size(); i += 7) {
    const Eigen::Vector3d q(small.x[i], small.y[i], small.z[i]);
    const LocalPlane* a = fresh.planes.planeAt(q);
    const LocalPlane* b = reused.planes.planeAt(q);
    ASSERT_EQ(a == nullptr, b == nullptr) << i;
    if (!a) continue;
    ++planes_found;
    EXPECT_EQ(a->mean, b->mean);
    EXPECT_EQ(a->normal, b->normal);
  }
  EXPECT_GT(planes_found, 100);
}

TEST(GridWorkspace, ARetargetedWorkspaceGivesTheJOfAFreshOne) {
  const PointArray a = cornerScene(3000, 7), b = cornerScene(5000, 8);
  const ReferenceGrids ga = buildReferenceGrids(a, edge(0.5), 3, 0.5, 1);
  // Fewer fine grids of another size: the workspace drops one and retargets the others.
  const ReferenceGrids gb = buildReferenceGrids(b, edge(0.4), 2, 0.5, 1);
  GridWorkspace reused(ga);
  reused.retarget(gb);
  GridWorkspace fresh(gb);
  ASSERT_EQ(reused.fine.size(), 2u);
  Pose6 p = Pose6::Zero();
  p << 0.1, -0.2, 0.0, 0.0, 0.01, 0.05;
  reused.setScan(a, a);
  fresh.setScan(a, a);
  EXPECT_EQ(reused.coarse(p), fresh.coarse(p));
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(reused.fine[k](p), fresh.fine[k](p));
  EXPECT_TRUE(reused.coarse.workingCopyRestored());
}
