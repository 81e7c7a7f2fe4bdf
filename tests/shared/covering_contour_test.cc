// The covering simplification (shared/silhouette/covering_contour.h) against the mask it
// traces: every foreground pixel centre inside, rings simple and apart, little area added.

#include "shared/silhouette/covering_contour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "shared/silhouette/silhouette_contour.h"
#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

// The polyhedral hull's contour settings (PolyhedralHullOptions), plain or covering.
ContourOptions HullSettings(bool cover) {
  ContourOptions options;
  options.tolerance_px = 0.6;
  options.smoothing_passes = 1;
  options.boundary_offset_px = cover ? 0.4 : 0.6;
  options.cover_pixel_centres = cover;
  return options;
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

double PointSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(1e-300, ab.squaredNorm()), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Closest approach of two segments, 0 if they cross.
double SegmentGap(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  const Eigen::Vector2d& d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  if (d1 * d2 < 0 && d3 * d4 < 0) return 0;
  return std::min(
      {PointSegment(a, c, d), PointSegment(b, c, d), PointSegment(c, a, b), PointSegment(d, a, b)});
}

// What a covering outline must satisfy, and what it costs.
struct Check {
  int centres_outside = 0;      // foreground pixel centres outside the outline
  double closest_centre = 1e9;  // smallest distance of a foreground centre to an edge
  double closest_edges = 1e9;   // closest approach of two non-adjacent edges (any rings)
  int misoriented = 0;          // outer rings not positive, holes not negative
  double added_area = 0;        // outline area minus foreground pixel count
};

Check CheckCovering(const cv::Mat& mask, const SilhouetteContours& contours) {
  Check check;
  struct Seg {
    Eigen::Vector2d a, b;
    size_t ring, index, size;
  };
  std::vector<Seg> segments;
  size_t ring_id = 0;
  auto add_ring = [&](const std::vector<Eigen::Vector2f>& ring) {
    for (size_t i = 0; i < ring.size(); ++i) {
      segments.push_back({ring[i].cast<double>(), ring[(i + 1) % ring.size()].cast<double>(),
                          ring_id, i, ring.size()});
    }
    ++ring_id;
  };
  for (const ContourPolygon& p : contours.polygons) {
    if (RingArea(p.outer) <= 0) ++check.misoriented;
    add_ring(p.outer);
    for (const auto& h : p.holes) {
      if (RingArea(h) >= 0) ++check.misoriented;
      add_ring(h);
    }
  }
  for (size_t i = 0; i < segments.size(); ++i) {
    for (size_t j = i + 1; j < segments.size(); ++j) {
      const Seg &s = segments[i], &t = segments[j];
      if (s.ring == t.ring) {
        const size_t gap = t.index - s.index;
        if (gap <= 1 || gap == s.size - 1) continue;
      }
      check.closest_edges = std::min(check.closest_edges, SegmentGap(s.a, s.b, t.a, t.b));
    }
  }
  int pixels = 0;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) continue;
      ++pixels;
      const Eigen::Vector2f p(static_cast<float>(x), static_cast<float>(y));
      if (!ContoursContain(contours, p)) ++check.centres_outside;
      for (const Seg& s : segments) {
        if ((s.a - p.cast<double>()).cwiseAbs().minCoeff() < 3 ||
            (s.b - p.cast<double>()).cwiseAbs().minCoeff() < 3) {
          check.closest_centre =
              std::min(check.closest_centre, PointSegment(p.cast<double>(), s.a, s.b));
        }
      }
    }
  }
  check.added_area = contours.Area() - pixels;
  return check;
}

// Limbs a pixel or two apart at many angles, a thin hole and two regions almost touching:
// where edges moved outwards would cross.
cv::Mat NarrowGapsMask() {
  cv::Mat mask(200, 260, CV_8U, cv::Scalar(0));
  for (int k = 0; k < 9; ++k) {
    const double angle = 0.17 * k;
    const cv::Point2f centre(static_cast<float>(30 + 25 * k), 60.f);
    const cv::RotatedRect limb(centre, cv::Size2f(5.f + static_cast<float>(k % 3), 80.f),
                               static_cast<float>(angle * 180 / 3.14159265));
    cv::Point2f corners[4];
    limb.points(corners);
    std::vector<cv::Point> polygon;
    for (const cv::Point2f& c : corners)
      polygon.emplace_back(
          cv::Point(static_cast<int>(std::lround(c.x)), static_cast<int>(std::lround(c.y))));
    cv::fillConvexPoly(mask, polygon, cv::Scalar(255));
  }
  cv::rectangle(mask, cv::Rect(20, 95, 220, 12), cv::Scalar(255), cv::FILLED);  // a shoulder
  cv::rectangle(mask, cv::Rect(30, 130, 200, 40), cv::Scalar(255), cv::FILLED);
  cv::line(mask, {40, 150}, {215, 143}, cv::Scalar(0), 1);                      // a thin hole
  cv::rectangle(mask, cv::Rect(30, 172, 90, 10), cv::Scalar(255), cv::FILLED);  // 1 px apart
  return mask;
}

// Expects every foreground centre covered, rings apart and oriented, and at most
// `max_point_ratio` times the plain simplification's points.
void ExpectCovers(const cv::Mat& mask, const std::string& what, double max_point_ratio) {
  const SilhouetteContours plain = ExtractContours(mask, HullSettings(false));
  const SilhouetteContours covering = ExtractContours(mask, HullSettings(true));
  const Check check = CheckCovering(mask, covering);
  const Check before = CheckCovering(mask, plain);
  std::printf(
      "%s: plain %zu points, %d centres outside, %+.0f px^2; covering %zu points, %d outside, "
      "closest centre %.3f px, closest edges %.3f px, %+.0f px^2\n",
      what.c_str(), plain.PointCount(), before.centres_outside, before.added_area,
      covering.PointCount(), check.centres_outside, check.closest_centre, check.closest_edges,
      check.added_area);
  EXPECT_EQ(check.centres_outside, 0) << what;
  // The margin (0.1 px), or less along a single outline step (the 0.4 px outline passes
  // 0.046 px from a centre at some staircase corners).
  EXPECT_GE(check.closest_centre, 0.04) << what;
  EXPECT_GE(check.closest_edges, 0.049) << what;  // the clearance, 0.05 px
  EXPECT_EQ(check.misoriented, 0) << what;
  EXPECT_EQ(covering.polygons.size(), plain.polygons.size()) << what;
  EXPECT_LE(static_cast<double>(covering.PointCount()),
            max_point_ratio * static_cast<double>(plain.PointCount()))
      << what;
}

TEST(CoveringContour, CoversEveryPixelCentreOfRandomBlobsWithHoles) {
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 12; ++trial) {
    cv::Mat mask = testing::RandomBlobMask(rng, 320, 240, 1 + trial % 4, false);
    const cv::Mat holes = testing::RandomBlobMask(rng, 320, 240, trial % 3, false);
    cv::Mat eroded;
    cv::erode(holes, eroded, cv::Mat(), cv::Point(-1, -1), 6);
    mask.setTo(0, eroded);
    // Measured: 1.4-3.2 times the plain points.
    ExpectCovers(mask, "blobs " + std::to_string(trial), 4.0);
  }
}

TEST(CoveringContour, CoversNarrowGapsWithoutCrossings) {
  // Measured: 5.5 times the plain points, which leave 114 centres outside: the slanted
  // 5-7 px limbs' staircases cost the most.
  ExpectCovers(NarrowGapsMask(), "narrow gaps", 6.0);
}

TEST(CoveringContour, AddsLittleAreaToAnEllipse) {
  const double a = 70.0, b = 45.0;
  const cv::Mat mask = testing::EllipseMask(320, 240, 160.3, 120.7, a, b, 0.4);
  const SilhouetteContours covering = ExtractContours(mask, HullSettings(true));
  ASSERT_EQ(covering.polygons.size(), 1u);
  const double area = 3.14159265 * a * b;
  std::printf("ellipse: %zu points, area %.1f (true %.1f)\n", covering.PointCount(),
              covering.Area(), area);
  // The outline runs about 0.1-0.6 px outside the true one: perimeter ~370 px.
  EXPECT_GT(covering.Area(), area);
  EXPECT_LT(covering.Area(), area + 0.5 * 370);
}

TEST(CoveringContour, ShortRingsPassThrough) {
  TracedRing ring;
  ring.centres = {{0, 0}, {1, 0}, {1, 1}};
  ring.outline = {{-0.5f, -0.5f}, {1.5f, -0.5f}, {1.5f, 1.5f}};
  const auto out = SimplifyCovering({ring}, {});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].size(), 3u);
}

}  // namespace
}  // namespace silnet
