// Face steps from a cut's interior through the hull (steps_to_interior.h): against the
// taxicab distance in a full box, around a wall the steps must go round, their bound, and the
// bridges the silhouette step ties inside.

#include "aggregator/stereo/steps_to_interior.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

VoxelGrid Box(int n) {
  return VoxelGrid::Empty(Eigen::Vector3d::Zero(), 0.01, {n, n, n});
}

VoxelGrid Full(int n) {
  VoxelGrid grid = Box(n);
  grid.occupied.assign(grid.size(), 1);
  return grid;
}

// Bridge(c) is a face-connected path of hull cells outside the interior from c to it.
void ExpectBridgeJoins(const StepsToInterior& steps, const VoxelGrid& hull,
                       const VoxelGrid& interior, size_t c) {
  const std::vector<size_t> bridge = steps.Bridge(c);
  ASSERT_EQ(static_cast<int>(bridge.size()), std::max(steps.Steps(c) - 1, 0));
  const auto adjacent = [&](size_t a, size_t b) {
    const auto n = static_cast<size_t>(hull.dims[0]);
    const long d = std::labs(static_cast<long>(a) - static_cast<long>(b));
    return d == 1 || d == static_cast<long>(n) || d == static_cast<long>(n * n);
  };
  size_t previous = c;
  for (size_t b : bridge) {
    EXPECT_TRUE(adjacent(previous, b));
    EXPECT_EQ(hull.occupied[b], 1);
    EXPECT_EQ(interior.occupied[b], 0);
    previous = b;
  }
  bool touches = false;
  for (size_t d : {size_t{1}, static_cast<size_t>(hull.dims[0]),
                   static_cast<size_t>(hull.dims[0] * hull.dims[1])}) {
    touches = touches || (previous >= d && interior.occupied[previous - d] != 0) ||
              (previous + d < interior.size() && interior.occupied[previous + d] != 0);
  }
  EXPECT_TRUE(touches) << "the bridge from " << c << " ends away from the interior";
}

TEST(StepsToInterior, TaxicabDistanceInAFullBoxUpToTheBound) {
  constexpr int kN = 15, kBound = 5;
  const VoxelGrid hull = Full(kN);
  VoxelGrid interior = Box(kN);
  interior.occupied[interior.Index(7, 7, 7)] = 1;
  interior.occupied[interior.Index(7, 8, 7)] = 1;
  const StepsToInterior steps = StepsToInterior::Compute(hull, interior, kBound);
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const int taxicab =
            std::abs(i - 7) + std::abs(k - 7) + std::min(std::abs(j - 7), std::abs(j - 8));
        const size_t c = hull.Index(i, j, k);
        EXPECT_EQ(steps.Steps(c), taxicab <= kBound ? taxicab : -1) << i << " " << j << " " << k;
        if (taxicab <= kBound) ExpectBridgeJoins(steps, hull, interior, c);
      }
}

TEST(StepsToInterior, GoesRoundCellsOutsideTheHull) {
  // A wall outside the hull at x = 5 with one door at (5, 0, *): the cell across the wall from
  // the interior is 1 + 2 * 4 + 1 steps away through the door, not 2.
  constexpr int kN = 10;
  VoxelGrid hull = Full(kN);
  for (int k = 0; k < kN; ++k)
    for (int j = 1; j < kN; ++j)
      hull.occupied[hull.Index(5, j, k)] = 0;
  VoxelGrid interior = Box(kN);
  interior.occupied[interior.Index(4, 4, 4)] = 1;
  const StepsToInterior steps = StepsToInterior::Compute(hull, interior, 12);
  EXPECT_EQ(steps.Steps(hull.Index(6, 4, 4)), 10);
  EXPECT_EQ(steps.Steps(hull.Index(5, 4, 4)), -1);  // not in the hull
  ExpectBridgeJoins(steps, hull, interior, hull.Index(6, 4, 4));
  EXPECT_EQ(steps.Steps(hull.Index(4, 4, 4)), 0);
  EXPECT_TRUE(steps.Bridge(hull.Index(4, 4, 4)).empty());
  EXPECT_TRUE(steps.Bridge(hull.Index(3, 4, 4)).empty());  // next to it: nothing between
}

TEST(StepsToInterior, RefusesBadBoundsAndLattices) {
  const VoxelGrid hull = Full(4);
  EXPECT_THROW(StepsToInterior::Compute(hull, Box(4), 0), CheckError);
  EXPECT_THROW(StepsToInterior::Compute(hull, Box(4), StepsToInterior::kMaxSteps + 1), CheckError);
  EXPECT_THROW(StepsToInterior::Compute(hull, Box(5), 3), CheckError);
  // No interior at all: every cell is out of reach.
  const StepsToInterior none = StepsToInterior::Compute(hull, Box(4), 3);
  EXPECT_EQ(none.Steps(0), -1);
}

}  // namespace
}  // namespace silnet::aggregator
