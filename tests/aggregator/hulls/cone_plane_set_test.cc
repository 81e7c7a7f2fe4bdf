// The cone plane set's cell index (aggregator/hulls/cone_plane_set.h): for image segments of
// every length and direction around the sphere ring's silhouettes, EdgesNearSegment offers
// every contour edge the segment meets, or declines a segment spanning more cells
// than allowed without touching the output. The pair index's arcs sort as std::sort would.

#include "aggregator/hulls/cone_plane_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
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

// SortArcs gives std::sort's order by (lo, plane) on arcs that come in runs as along a contour
// (rising, falling, flat stretches, repeated angles where two edges share a turning point) and
// on shuffled ones, with the buffer kept from call to call.
TEST(ConePlaneSetTest, SortArcsOrdersByAngleThenPlane) {
  std::mt19937 random(11);
  std::vector<EdgeArc> buffer;
  for (int trial = 0; trial < 500; ++trial) {
    const int count = std::uniform_int_distribution<int>(0, 300)(random);
    // Planes are distinct, as in a pair index, but not in the arcs' order.
    std::vector<int> planes(static_cast<size_t>(count));
    std::iota(planes.begin(), planes.end(), 0);
    std::shuffle(planes.begin(), planes.end(), random);
    std::vector<EdgeArc> arcs;
    double angle = std::uniform_real_distribution<double>(-2, 2)(random);
    double step = 0.01;
    for (int k = 0; k < count; ++k) {
      const int turn = std::uniform_int_distribution<int>(0, 19)(random);
      if (turn == 0) step = -step;  // a turning point of the contour
      if (turn == 1) step = 0;      // a flat stretch: equal angles
      if (turn == 2) step = trial % 2 ? 0.01 : -0.01;
      angle += step * std::uniform_real_distribution<double>(0.5, 1.5)(random);
      const double other = angle + std::uniform_real_distribution<double>(0, 0.02)(random);
      arcs.push_back({angle, other, planes[static_cast<size_t>(k)]});
    }
    if (trial % 5 == 0) std::shuffle(arcs.begin(), arcs.end(), random);
    std::vector<EdgeArc> expected = arcs;
    std::sort(expected.begin(), expected.end(), [](const EdgeArc& x, const EdgeArc& y) {
      return x.lo != y.lo ? x.lo < y.lo : x.plane < y.plane;
    });
    SortArcs(arcs, buffer);
    ASSERT_EQ(arcs.size(), expected.size());
    for (size_t k = 0; k < arcs.size(); ++k) {
      ASSERT_EQ(arcs[k].lo, expected[k].lo) << "trial " << trial << " arc " << k;
      ASSERT_EQ(arcs[k].hi, expected[k].hi) << "trial " << trial << " arc " << k;
      ASSERT_EQ(arcs[k].plane, expected[k].plane) << "trial " << trial << " arc " << k;
    }
  }
}

}  // namespace
}  // namespace silnet::aggregator
