// The boundary loops of a face's trapezoids: the sweep's cuts dropped, splits, holes, and the
// slivers and spikes of near-degenerate faces, on hand-made trapezoids with known answers.

#include "aggregator/hulls/face_boundary_loops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace silnet::aggregator {
namespace {

Trapezoid Make(double a, double b, Corner bottom_a, Corner bottom_b, Corner top_a, Corner top_b) {
  Trapezoid t;
  t.a = a;
  t.b = b;
  t.bottom_a = bottom_a;
  t.bottom_b = bottom_b;
  t.top_a = top_a;
  t.top_b = top_b;
  return t;
}

std::vector<int> Vertices(const std::vector<LoopPoint>& loop) {
  std::vector<int> vertices;
  for (const LoopPoint& point : loop)
    vertices.push_back(point.vertex);
  return vertices;
}

// True if `loop` is `expected` up to where it starts.
bool SameCycle(std::vector<int> loop, const std::vector<int>& expected) {
  if (loop.size() != expected.size()) return false;
  for (size_t k = 0; k < loop.size(); ++k) {
    if (loop == expected) return true;
    std::rotate(loop.begin(), loop.begin() + 1, loop.end());
  }
  return false;
}

TEST(FaceBoundaryLoopsTest, OneTrapezoidIsItsFourCornersCounterClockwise) {
  std::vector<std::vector<LoopPoint>> loops;
  ASSERT_TRUE(FaceBoundaryLoops({Make(0, 1, {0, 0}, {0, 1}, {1, 3}, {1, 2})}, 1.0, loops));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(SameCycle(Vertices(loops[0]), {0, 1, 2, 3}));
}

TEST(FaceBoundaryLoopsTest, TheSweepsCutsAreLeftOut) {
  std::vector<std::vector<LoopPoint>> loops;
  ASSERT_TRUE(FaceBoundaryLoops({Make(0, 0.5, {0, 0}, {0, -2}, {1, 3}, {1, -3}),
                                 Make(0.5, 1, {0, -2}, {0, 1}, {1, -3}, {1, 2})},
                                1.0, loops));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(SameCycle(Vertices(loops[0]), {0, 1, 2, 3}));
}

TEST(FaceBoundaryLoopsTest, AnIntervalSplitAtAVertexLeavesANotch) {
  // Two lines of another view start at vertex 10 inside the face: outside between them.
  std::vector<std::vector<LoopPoint>> loops;
  ASSERT_TRUE(FaceBoundaryLoops({Make(0, 0.5, {0, 0}, {0, -2}, {2, 3}, {2, -3}),
                                 Make(0.5, 1, {0, -2}, {0, 1}, {1, 10}, {0.5, 11}),
                                 Make(0.5, 1, {1, 10}, {1.5, 12}, {2, -3}, {2, 2})},
                                2.0, loops));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(SameCycle(Vertices(loops[0]), {0, 1, 11, 10, 12, 2, 3}));
}

TEST(FaceBoundaryLoopsTest, AHoleIsAClockwiseLoopOfItsOwn) {
  // A triangle of another view's silhouette, inside the face: vertices 10, 11, 12.
  std::vector<std::vector<LoopPoint>> loops;
  ASSERT_TRUE(FaceBoundaryLoops({Make(0, 0.3, {0, 0}, {0, -2}, {2, 3}, {2, -3}),
                                 Make(0.3, 0.5, {0, -2}, {0, -4}, {1, 10}, {0.8, 11}),
                                 Make(0.3, 0.5, {1, 10}, {1, -5}, {2, -3}, {2, -6}),
                                 Make(0.5, 0.7, {0, -4}, {0, -7}, {0.8, 11}, {1, 12}),
                                 Make(0.5, 0.7, {1, -5}, {1, 12}, {2, -6}, {2, -8}),
                                 Make(0.7, 1, {0, -7}, {0, 1}, {2, -8}, {2, 2})},
                                2.0, loops));
  ASSERT_EQ(loops.size(), 2u);
  const bool outer_first = loops[0].size() == 4;
  EXPECT_TRUE(SameCycle(Vertices(loops[outer_first ? 0 : 1]), {0, 1, 2, 3}));
  EXPECT_TRUE(SameCycle(Vertices(loops[outer_first ? 1 : 0]), {11, 10, 12}));
}

TEST(FaceBoundaryLoopsTest, ASliverOfASlabLeavesNoSpike) {
  // A contour vertex of another view (10) at lambda 1e-13: the line from it to the left side is
  // too short for the sweep, so the region's upper line drops there from w 2 to 1.5. The
  // boundary runs up the sliver's side and back down the face's own side: a zero-area spike.
  std::vector<std::vector<LoopPoint>> loops;
  ASSERT_TRUE(FaceBoundaryLoops({Make(0, 1e-13, {0, 0}, {0, -2}, {2, 3}, {2, -3}),
                                 Make(1e-13, 1, {0, -2}, {0, 1}, {1.5, 10}, {1.5, 2})},
                                2.0, loops));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(SameCycle(Vertices(loops[0]), {0, 1, 2, 10}));
}

TEST(FaceBoundaryLoopsTest, AFaceWithoutAreaHasNoLoop) {
  std::vector<std::vector<LoopPoint>> loops;
  EXPECT_TRUE(FaceBoundaryLoops({Make(0, 1, {0, 0}, {0, 1}, {0, 0}, {0, 1})}, 1.0, loops));
  EXPECT_TRUE(loops.empty());
  // A sliver 1e-15 wide inside the chart whose corners all but coincide (the Middlebury
  // temple has one).
  EXPECT_TRUE(
      FaceBoundaryLoops({Make(5.2582927419725e-14, 5.36151688901388e-14, {1.71866669376, 59},
                              {1.73062801507, 60}, {1.73062801507, -76}, {1.73062801507, 60})},
                        0.5, loops));
  EXPECT_TRUE(loops.empty());
}

}  // namespace
}  // namespace silnet::aggregator
