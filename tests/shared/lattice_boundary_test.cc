#include "shared/silhouette/lattice_boundary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/silhouette/melkman_hull.h"
#include "shared/silhouette/silhouette_hull.h"
#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

double Support(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& n) {
  double h = -1e300;
  for (const Eigen::Vector2d& p : points)
    h = std::max(h, n.dot(p));
  return h;
}

TEST(LatticeBoundary, GapIsHalfTheLatticeSpacingAlongShortDirections) {
  EXPECT_DOUBLE_EQ(ExpectedBoundaryGap({5, 0}), 0.5);
  EXPECT_DOUBLE_EQ(ExpectedBoundaryGap({0, -3}), 0.5);
  EXPECT_NEAR(ExpectedBoundaryGap({-4, 4}), 0.5 / std::sqrt(2.0), 1e-12);
  EXPECT_DOUBLE_EQ(ExpectedBoundaryGap({17, 5}), 0.25);
  EXPECT_DOUBLE_EQ(ExpectedBoundaryGap({6, 3}), 0.25);  // (2, 1): 0.22 < 0.25
}

TEST(LatticeBoundary, MovesEveryEdgeOutByItsGapAndKeepsEveryCentreInside) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Mat mask = testing::RandomBlobMask(rng, 160, 120, 1 + trial % 3, false);
    std::vector<cv::Point> pixels;
    cv::findNonZero(mask, pixels);
    std::vector<Eigen::Vector2d> centres;
    for (const cv::Point& p : pixels)
      centres.emplace_back(p.x, p.y);
    std::vector<cv::Point> hull_points;
    cv::convexHull(pixels, hull_points, /*clockwise=*/false);
    std::vector<Eigen::Vector2d> polygon;
    for (const cv::Point& p : hull_points)
      polygon.emplace_back(p.x, p.y);
    polygon = MelkmanHull(polygon);
    if (polygon.size() < 3) continue;
    const std::vector<Eigen::Vector2d> boundary = LatticeBoundaryPolygon(polygon, 160, 120);
    ASSERT_GE(boundary.size(), 3u) << "trial " << trial;
    const size_t n = boundary.size();
    for (size_t i = 0; i < n; ++i) {
      ASSERT_GT(Orientation(boundary[i], boundary[(i + 1) % n], boundary[(i + 2) % n]), -1e-9)
          << "trial " << trial << ": not convex";
    }
    // Along each edge normal of the centres' hull the boundary lies beyond the centres by at
    // most the edge's gap (exactly that where the edge survives) and at least the smallest gap.
    for (size_t i = 0; i < polygon.size(); ++i) {
      const Eigen::Vector2d d = polygon[(i + 1) % polygon.size()] - polygon[i];
      const Eigen::Vector2d normal = Eigen::Vector2d(d.y(), -d.x()).normalized();
      const double moved = Support(boundary, normal) - Support(centres, normal);
      EXPECT_LE(moved, ExpectedBoundaryGap(d) + 1e-9) << "trial " << trial << " edge " << i;
      EXPECT_GE(moved, 0.25 - 1e-9) << "trial " << trial << " edge " << i;
    }
    // Every foreground centre lies inside, with room to spare.
    SilhouetteHull hull(boundary, std::vector<bool>(n, false));
    for (const Eigen::Vector2d& c : centres)
      ASSERT_TRUE(hull.Contains(c)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace silnet
