// Ear clipping of loops with holes: every point used, no point added, the region's area
// exactly covered, and bad loops reported.

#include "aggregator/hulls/loop_triangulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>

namespace silnet::aggregator {
namespace {

using Loop = std::vector<Eigen::Vector2d>;

double SignedArea(const Loop& loop) {
  double area = 0;
  for (size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector2d& a = loop[k];
    const Eigen::Vector2d& b = loop[(k + 1) % loop.size()];
    area += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * area;
}

Loop Reversed(Loop loop) {
  std::reverse(loop.begin(), loop.end());
  return loop;
}

Loop Rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// Checks the triangulation of `loops`: n - 2 + 2 h triangles for n points and h holes per
// outer loop, each point used, every triangle counter-clockwise (or flat), the areas adding
// up to the region's, and every loop edge an edge of exactly one triangle.
void ExpectTriangulates(const std::vector<Loop>& loops) {
  const LoopTriangulation result = TriangulateLoops(loops);
  ASSERT_TRUE(result.success) << result.reason;
  std::vector<Eigen::Vector2d> points;
  size_t holes = 0, outers = 0;
  double region = 0;
  for (const Loop& loop : loops) {
    points.insert(points.end(), loop.begin(), loop.end());
    const double area = SignedArea(loop);
    region += area;
    (area > 0 ? outers : holes) += 1;
  }
  EXPECT_EQ(result.triangles.size(), points.size() - 2 * outers + 2 * holes);
  std::set<int> used;
  std::map<std::pair<int, int>, int> edges;
  double total = 0;
  for (const auto& t : result.triangles) {
    const Eigen::Vector2d& a = points[static_cast<size_t>(t[0])];
    const Eigen::Vector2d& b = points[static_cast<size_t>(t[1])];
    const Eigen::Vector2d& c = points[static_cast<size_t>(t[2])];
    const double area = 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    EXPECT_GE(area, -1e-12);
    total += area;
    for (int k = 0; k < 3; ++k) {
      used.insert(t[static_cast<size_t>(k)]);
      ++edges[{t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]}];
    }
  }
  EXPECT_EQ(used.size(), points.size());
  EXPECT_NEAR(total, region, 1e-12 * std::max(1.0, std::abs(region)));
  int first = 0;
  for (const Loop& loop : loops) {
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) {
      const std::pair<int, int> edge(first + k, first + (k + 1) % n);
      EXPECT_EQ(edges[edge], 1) << "loop edge " << edge.first << "-" << edge.second;
    }
    first += n;
  }
}

TEST(LoopTriangulationTest, ConvexAndConcavePolygons) {
  ExpectTriangulates({Rectangle(0, 0, 1, 1)});
  ExpectTriangulates({{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}});  // an L
  // A comb: reflex vertices that block many candidate ears.
  Loop comb = {{0, 0}, {5, 0}, {5, 1}};
  for (int k = 4; k >= 0; --k) {
    comb.push_back({k + 0.9, 1});
    comb.push_back({k + 0.5, 3});
    comb.push_back({k + 0.1, 1});
  }
  comb.push_back({0, 1});
  ExpectTriangulates({comb});
}

TEST(LoopTriangulationTest, CollinearPointsStayVertices) {
  // Points on the sides, as the hull's faces have where a neighbouring face bends.
  ExpectTriangulates({{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}});
  ExpectTriangulates({{{0, 0}, {1, 0}, {2, 0}, {1, 1}, {0, 2}, {0, 1}}});  // a triangle
}

TEST(LoopTriangulationTest, HolesAreJoinedToTheirOuterLoop) {
  ExpectTriangulates({Rectangle(0, 0, 4, 4), Reversed(Rectangle(1, 1, 2, 2))});
  ExpectTriangulates({Rectangle(0, 0, 6, 4), Reversed(Rectangle(1, 1, 2, 3)),
                      Reversed(Rectangle(3, 1, 5, 2)), Reversed(Rectangle(3, 2.5, 4, 3.5))});
  // A hole level with the outer loop's vertices (the bridge ray passes through them).
  ExpectTriangulates({{{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 2}, {1, 2}, {1, 4}, {0, 4}},
                      Reversed(Rectangle(2.5, 2, 3.5, 3))});
  // Two islands, one inside the other's hole.
  ExpectTriangulates(
      {Rectangle(0, 0, 10, 10), Reversed(Rectangle(2, 2, 8, 8)), Rectangle(4, 4, 6, 6)});
}

TEST(LoopTriangulationTest, LoopsThatTouchAtAVertex) {
  ExpectTriangulates({Rectangle(0, 0, 1, 1), Rectangle(1, 1, 2, 2)});
  // A hole touching the outer loop at one of its corners.
  ExpectTriangulates({Rectangle(0, 0, 4, 4), {{2, 0}, {1, 1}, {3, 1}}});
}

TEST(LoopTriangulationTest, RandomStarPolygonsWithAHole) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> radius(1.5, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    Loop star;
    const int n = 5 + trial % 40;
    for (int k = 0; k < n; ++k) {
      const double angle = 2 * std::numbers::pi * k / n;
      const double r = radius(random);
      star.push_back({r * std::cos(angle), r * std::sin(angle)});
    }
    Loop hole;
    for (int k = 0; k < 7; ++k) {
      const double angle = -2 * std::numbers::pi * k / 7;
      hole.push_back({0.8 * std::cos(angle), 0.8 * std::sin(angle)});
    }
    ExpectTriangulates({star, hole});
  }
}

TEST(LoopTriangulationTest, ReportsLoopsThatAreNoRegion) {
  EXPECT_FALSE(TriangulateLoops({{{0, 0}, {1, 0}}}).success);
  EXPECT_FALSE(TriangulateLoops({{{0, 0}, {1, 0}, {2, 0}}}).success);  // no area
  const LoopTriangulation bowtie = TriangulateLoops({{{0, 0}, {2, 2}, {2, 0}, {0, 2}, {-1, 1}}});
  EXPECT_FALSE(bowtie.success);
  EXPECT_FALSE(TriangulateLoops(
                   {Rectangle(0, 0, 1, 1), Rectangle(3, 0, 4, 1), Reversed(Rectangle(5, 0, 6, 1))})
                   .success);  // a hole outside every outer loop
}

}  // namespace
}  // namespace silnet::aggregator
