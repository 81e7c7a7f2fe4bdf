#include "shared/silhouette/silhouette_hull.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/silhouette/melkman_hull.h"
#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

double PointPolygonDistance(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly) {
  double best = 1e300;
  for (size_t i = 0; i < poly.size(); ++i) {
    best = std::min(best, PointSegmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
  }
  return best;
}

// Hausdorff distance between two convex polygons (their boundaries).
double Hausdorff(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  double worst = 0.0;
  for (const auto& p : a)
    worst = std::max(worst, PointPolygonDistance(p, b));
  for (const auto& p : b)
    worst = std::max(worst, PointPolygonDistance(p, a));
  return worst;
}

std::vector<Eigen::Vector2d> OpenCvHull(const cv::Mat& mask) {
  std::vector<cv::Point> points, hull;
  cv::findNonZero(mask, points);
  cv::convexHull(points, hull);
  std::vector<Eigen::Vector2d> out;
  for (const cv::Point& p : hull)
    out.emplace_back(p.x, p.y);
  return out;
}

TEST(MelkmanHull, EqualsOpenCvOnRandomStarPolygons) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    // A star-shaped (hence simple) polygon.
    const int n = 3 + static_cast<int>(u(rng) * 60);
    std::vector<double> angles;
    for (int i = 0; i < n; ++i)
      angles.push_back(6.283185307 * u(rng));
    std::sort(angles.begin(), angles.end());
    std::vector<Eigen::Vector2d> polyline;
    std::vector<cv::Point2f> cv_points;
    for (double a : angles) {
      const double r = 10 + 90 * u(rng);
      polyline.emplace_back(r * std::cos(a), r * std::sin(a));
      polyline.back() = polyline.back().cast<float>().cast<double>();
      cv_points.emplace_back(static_cast<float>(polyline.back().x()),
                             static_cast<float>(polyline.back().y()));
    }
    const std::vector<Eigen::Vector2d> hull = MelkmanHull(polyline);
    std::vector<cv::Point2f> reference;
    cv::convexHull(cv_points, reference);
    std::vector<Eigen::Vector2d> ref;
    for (const auto& p : reference)
      ref.emplace_back(p.x, p.y);
    ASSERT_GE(hull.size(), 3u);
    EXPECT_LT(Hausdorff(hull, ref), 1e-4) << "trial " << trial;
    for (size_t i = 0; i < hull.size(); ++i) {
      EXPECT_GT(Orientation(hull[i], hull[(i + 1) % hull.size()], hull[(i + 2) % hull.size()]),
                0.0);
    }
  }
}

TEST(MelkmanHull, HandlesCollinearAndTinyInputs) {
  EXPECT_TRUE(MelkmanHull({}).empty());
  EXPECT_EQ(MelkmanHull({{1, 1}}).size(), 1u);
  const auto line = MelkmanHull({{0, 0}, {1, 1}, {2, 2}, {3, 3}});
  ASSERT_EQ(line.size(), 2u);
  EXPECT_EQ(line[0], Eigen::Vector2d(0, 0));
  EXPECT_EQ(line[1], Eigen::Vector2d(3, 3));
}

TEST(SilhouetteHull, LiesAQuarterToThreeQuartersOfAPixelBeyondTheCentresHull) {
  std::mt19937_64 rng(6);
  for (int trial = 0; trial < 300; ++trial) {
    const cv::Mat mask = testing::RandomBlobMask(rng, 160, 120, 1 + trial % 4, trial % 3 == 0);
    if (cv::countNonZero(mask) == 0) continue;
    MaskSummary summary;
    const SilhouetteHull hull = ComputeSilhouetteHull(mask, &summary);
    const auto reference = OpenCvHull(mask);
    if (reference.size() < 3) continue;
    for (int k = 0; k < 360; ++k) {
      const double a = k * EIGEN_PI / 180.0;
      const Eigen::Vector2d n(std::cos(a), std::sin(a));
      double ours = -1e300, centres = -1e300;
      for (const Eigen::Vector2d& v : hull.vertices())
        ours = std::max(ours, n.dot(v));
      for (const Eigen::Vector2d& v : reference)
        centres = std::max(centres, n.dot(v));
      // 0.25 px at least, less the rounding to the vertex grid.
      ASSERT_GE(ours - centres, 0.25 - kHullVertexStep) << "trial " << trial << " direction " << k;
      ASSERT_LE(ours - centres, 0.75) << "trial " << trial << " direction " << k;
    }
    EXPECT_EQ(summary.foreground_pixels, cv::countNonZero(mask));
    EXPECT_GT(hull.Area(), 0.0);
    // Every foreground pixel centre is inside.
    std::vector<cv::Point> points;
    cv::findNonZero(mask, points);
    for (const cv::Point& p : points)
      ASSERT_TRUE(hull.Contains(Eigen::Vector2d(p.x, p.y)));
  }
}

TEST(SilhouetteHull, TheTangentTableIncreasesAroundTheHull) {
  std::mt19937_64 rng(7);
  const cv::Mat mask = testing::RandomBlobMask(rng, 320, 240, 3, false);
  const SilhouetteHull hull = ComputeSilhouetteHull(mask);
  int wraps = 0;
  for (int i = 0; i < hull.size(); ++i) {
    if (hull.edge_angle((i + 1) % hull.size()) < hull.edge_angle(i)) ++wraps;
  }
  EXPECT_EQ(wraps, 1);
}

TEST(SilhouetteHull, MarksEdgesOnTheImageBorderAsClipped) {
  // A disc cut by the left and bottom borders.
  const cv::Mat mask = testing::EllipseMask(100, 80, 5, 75, 30, 25, 0.0);
  const SilhouetteHull hull = ComputeSilhouetteHull(mask);
  int left = 0, bottom = 0, other = 0;
  for (int i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull.vertex(i);
    const Eigen::Vector2d& b = hull.vertex((i + 1) % hull.size());
    if (!hull.edge_clipped(i)) continue;
    if (a.x() == -0.5 && b.x() == -0.5) {
      ++left;
    } else if (a.y() == 79.5 && b.y() == 79.5) {
      ++bottom;
    } else {
      ++other;
    }
  }
  EXPECT_EQ(left, 1);
  EXPECT_EQ(bottom, 1);
  EXPECT_EQ(other, 0);
  EXPECT_TRUE(hull.any_clipped());
  // A silhouette inside the image is not clipped.
  EXPECT_FALSE(
      ComputeSilhouetteHull(testing::EllipseMask(100, 80, 50, 40, 20, 10, 0.3)).any_clipped());
}

TEST(SilhouetteHull, EmptyFullAndSinglePixelMasks) {
  cv::Mat mask(40, 30, CV_8U, cv::Scalar(0));
  MaskSummary summary;
  EXPECT_TRUE(ComputeSilhouetteHull(mask, &summary).empty());
  EXPECT_EQ(summary.foreground_pixels, 0);
  mask.at<uint8_t>(10, 7) = 1;
  const SilhouetteHull dot = ComputeSilhouetteHull(mask);
  EXPECT_EQ(dot.size(), 4);
  EXPECT_NEAR(dot.Area(), 1.0, 1e-12);  // the pixel's square
  mask.setTo(255);
  // All white: the image rectangle (rows and columns lie half a pixel beyond their centres);
  // the border edges are clipped and no vertex gives a real tangent.
  const SilhouetteHull full = ComputeSilhouetteHull(mask, &summary);
  EXPECT_EQ(full.size(), 4);
  EXPECT_NEAR(full.Area(), 30.0 * 40.0, 1e-9);
  int clipped = 0;
  for (int i = 0; i < full.size(); ++i) {
    clipped += full.edge_clipped(i) ? 1 : 0;
    EXPECT_TRUE(full.vertex_on_clipped_edge(i));
  }
  EXPECT_EQ(clipped, 4);
  EXPECT_TRUE(summary.touches_border);
  cv::Mat wrong(4, 4, CV_32F);
  EXPECT_ANY_THROW(ComputeSilhouetteHull(wrong));
}

}  // namespace
}  // namespace silnet
