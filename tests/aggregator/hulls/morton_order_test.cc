// The Morton curve that lays points out in memory: codes, clamping, order.

#include "aggregator/hulls/morton_order.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace silnet::aggregator {
namespace {

TEST(MortonCurveTest, CodesInterleaveTheAxesAndClampToTheBox) {
  const MortonCurve curve(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 4, 8)));
  const uint64_t last = (uint64_t{1} << 63) - 1;  // every one of the 63 bits
  EXPECT_EQ(curve.Code({0, 0, 0}), 0u);
  EXPECT_EQ(curve.Code({2, 4, 8}), last);
  // The top cell of one axis sets that axis's bits only: x every third bit from bit 0.
  EXPECT_EQ(curve.Code({2, 0, 0}), 0x1249249249249249ULL & last);
  EXPECT_EQ(curve.Code({0, 4, 0}), (0x1249249249249249ULL << 1) & last);
  EXPECT_EQ(curve.Code({0, 0, 8}), (0x1249249249249249ULL << 2) & last);
  // Beyond the box: clamped to its sides; NaN to the low side.
  EXPECT_EQ(curve.Code({-5, -5, -5}), 0u);
  EXPECT_EQ(curve.Code({50, 50, 50}), last);
  EXPECT_EQ(curve.Code({std::numeric_limits<double>::quiet_NaN(), 4, 8}),
            last & ~(0x1249249249249249ULL & last));
}

TEST(MortonCurveTest, OrdersTheCellsOfACubeInZOrderAndHandlesFlatSets) {
  // The eight octant centres of a cube, listed backwards: Z-order is x fastest, then y, then z.
  std::vector<Eigen::Vector3d> centres;
  for (int k = 7; k >= 0; --k)
    centres.emplace_back(0.25 + 0.5 * (k & 1), 0.25 + 0.5 * (k >> 1 & 1), 0.25 + 0.5 * (k >> 2));
  centres.emplace_back(0, 0, 0);  // the box's corners, so the octants are the box's
  centres.emplace_back(1, 1, 1);
  const std::vector<uint32_t> order = MortonCurve(centres).Order(centres);
  const std::vector<uint32_t> expected = {8, 7, 6, 5, 4, 3, 2, 1, 0, 9};
  EXPECT_EQ(order, expected);

  // All points in one plane: the flat axis maps to cell 0, the others still order them.
  const std::vector<Eigen::Vector3d> flat = {{1, 0, 3}, {0, 1, 3}, {0, 0, 3}, {1, 1, 3}};
  const std::vector<uint32_t> flat_order = MortonCurve(flat).Order(flat);
  EXPECT_EQ(flat_order, (std::vector<uint32_t>{2, 0, 1, 3}));
}

}  // namespace
}  // namespace silnet::aggregator
