// The cone plane set's cell index (aggregator/hulls/cone_plane_set.h): for image segments of
// every length and direction around the sphere ring's silhouettes, EdgesNearSegment offers
// every contour edge the segment meets, or declines a segment spanning more cells
// than allowed without touching the output.

#include "aggregator/hulls/cone_plane_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "aggregator/hulls/viewing_cone_bounds.h"
#include "tests/aggregator/hulls/sphere_scene.h"

namespace silnet::aggregator {
namespace {

// Twice the signed area of the triangle a, b, c.
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

// True if the closed segments a-b and p-q share a point (collinear overlaps excluded).
bool SegmentsMeet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p,
                  const Eigen::Vector2d& q) {
  const double d1 = Cross(a, b, p), d2 = Cross(a, b, q);
  const double d3 = Cross(p, q, a), d4 = Cross(p, q, b);
  return ((d1 <= 0 && d2 >= 0) || (d1 >= 0 && d2 <= 0)) &&
         ((d3 <= 0 && d4 >= 0) || (d3 >= 0 && d4 <= 0)) && (d1 != 0 || d2 != 0);
}

TEST(ConePlaneSetTest, EdgesNearSegmentOffersEveryEdgeTheSegmentMeets) {
  const hull_testing::SphereScene scene = hull_testing::MakeSphereScene(0.0, true);
  std::vector<SilhouetteContours> contours;
  for (const cv::Mat& mask : scene.masks)
    contours.push_back(ExtractContours(mask, ContourOptions{}));
  const ViewingConeBounds bounds = ComputeViewingConeBounds(scene.cameras, scene.masks);
  ASSERT_TRUE(bounds.success) << bounds.reason;
  const ConePlaneSet set(scene.cameras, contours, bounds.box);

  std::mt19937 random(7);
  size_t met = 0, declined = 0;
  for (int view = 0; view < static_cast<int>(set.Views()); ++view) {
    Eigen::AlignedBox2d extent;
    for (const ConePlane& plane : set.Planes())
      if (plane.view == view) extent.extend(plane.p);
    ASSERT_FALSE(extent.isEmpty());
    std::uniform_real_distribution<double> x(extent.min().x() - 20, extent.max().x() + 20);
    std::uniform_real_distribution<double> y(extent.min().y() - 20, extent.max().y() + 20);
    std::uniform_real_distribution<double> angle(0, 2 * M_PI);
    for (int trial = 0; trial < 2000; ++trial) {
      const Eigen::Vector2d a(x(random), y(random));
      // Lengths from a tenth of a pixel to about three hundred, horizontal and vertical ones too.
      const double length = std::pow(10.0, std::uniform_real_distribution<double>(-1, 2.5)(random));
      const double theta = trial % 10 == 0 ? 0 : trial % 10 == 1 ? M_PI / 2 : angle(random);
      const Eigen::Vector2d b = a + length * Eigen::Vector2d(std::cos(theta), std::sin(theta));
      std::vector<int> out = {-7};  // what was there before stays
      if (!set.EdgesNearSegment(view, a, b, 16, out)) {
        EXPECT_EQ(out, std::vector<int>{-7});
        ++declined;
        continue;
      }
      ASSERT_FALSE(out.empty());
      EXPECT_EQ(out.front(), -7);
      const std::set<int> offered(out.begin() + 1, out.end());
      for (int index = 0; index < static_cast<int>(set.Planes().size()); ++index) {
        const ConePlane& plane = set.Plane(index);
        if (plane.view != view || !SegmentsMeet(a, b, plane.p, plane.q)) continue;
        ++met;
        EXPECT_TRUE(offered.count(index))
            << "view " << view << " segment (" << a.transpose() << ") - (" << b.transpose()
            << ") meets plane " << index << " but was not offered it";
      }
    }
  }
  // The trials reach both outcomes and many edges.
  EXPECT_GT(met, 1000u) << met;
  EXPECT_GT(declined, 100u) << declined;
}

}  // namespace
}  // namespace silnet::aggregator
