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
