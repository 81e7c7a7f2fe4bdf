#include "shared/silhouette/silhouette_contour.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/silhouette/contour_codec.h"
#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

TEST(SilhouetteContour, OutlinesLieOnTheTrueBoundaryAtSubPixelPrecision) {
  // An ellipse sampled at pixel centres: contour points are close to the analytic outline.
  const double cx = 160.3, cy = 120.7, a = 70.0, b = 45.0, angle = 0.4;
  const cv::Mat mask = testing::EllipseMask(320, 240, cx, cy, a, b, angle);
  ContourOptions options;
  options.tolerance_px = 0.25;
  const SilhouetteContours contours = ExtractContours(mask, options);
  ASSERT_EQ(contours.polygons.size(), 1u);
  EXPECT_TRUE(contours.polygons[0].holes.empty());
  // Distance to the ellipse, approximately: |r - 1| scaled by the local radius.
  auto distance = [&](double px, double py) {
    const double dx = px - cx, dy = py - cy;
    const double u = (std::cos(angle) * dx + std::sin(angle) * dy) / a;
    const double v = (-std::sin(angle) * dx + std::cos(angle) * dy) / b;
    const double r = std::sqrt(u * u + v * v);
    return std::abs(r - 1.0) * std::sqrt(dx * dx + dy * dy) / r;
  };
  double sum = 0.0, worst = 0.0;
  for (const Eigen::Vector2f& p : contours.polygons[0].outer) {
    sum += distance(p.x(), p.y());
    worst = std::max(worst, distance(p.x(), p.y()));
  }
  const double mean = sum / static_cast<double>(contours.polygons[0].outer.size());
  // The boundary pixel centres themselves are about half a pixel inside.
  std::vector<std::vector<cv::Point>> traced;
  cv::findContours(mask.clone(), traced, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  double centre_sum = 0.0;
  for (const cv::Point& p : traced[0])
    centre_sum += distance(p.x, p.y);
  const double centre_mean = centre_sum / static_cast<double>(traced[0].size());
  std::printf("mean distance to the true outline: %.3f px (pixel centres: %.3f px), worst %.3f\n",
              mean, centre_mean, worst);
  EXPECT_LT(mean, 0.35);
  EXPECT_LT(mean, 0.75 * centre_mean);
  EXPECT_LT(worst, 0.8);
  // The enclosed area matches the ellipse better than the pixel count's half-pixel bias.
  EXPECT_NEAR(contours.Area(), 3.14159265 * a * b, 0.01 * 3.14159265 * a * b);
  EXPECT_GT(RingArea(contours.polygons[0].outer), 0.0);
}

TEST(SilhouetteContour, SmoothingTheStaircaseKeepsFewerPointsAndTheSilhouette) {
  // The polyhedral hull's settings (one smoothing pass, outline 0.6 px out) against the plain
  // outline at the same tolerance: far fewer points, and the outline still encloses the
  // silhouette's pixel centres and follows the true boundary.
  const double cx = 160.3, cy = 120.7, a = 70.0, b = 45.0, angle = 0.4;
  const cv::Mat mask = testing::EllipseMask(320, 240, cx, cy, a, b, angle);
  ContourOptions plain;
  plain.tolerance_px = 0.6;
  ContourOptions smoothed = plain;
  smoothed.smoothing_passes = 1;
  smoothed.boundary_offset_px = 0.6;
  const SilhouetteContours rough = ExtractContours(mask, plain);
  const SilhouetteContours smooth = ExtractContours(mask, smoothed);
  ASSERT_EQ(smooth.polygons.size(), 1u);
  int outside = 0, pixels = 0;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) continue;
      ++pixels;
      if (!ContoursContain(smooth, Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y))))
        ++outside;
    }
  }
  std::printf("points %zu (plain %zu); pixel centres outside %d of %d; area %.1f (true %.1f)\n",
              smooth.PointCount(), rough.PointCount(), outside, pixels, smooth.Area(),
              3.14159265 * a * b);
  // Measured: 30 points against 56, 17 of 9899 pixel centres outside (0.17 %).
  EXPECT_LT(static_cast<double>(smooth.PointCount()),
            0.7 * static_cast<double>(rough.PointCount()));
  EXPECT_LE(outside, pixels / 250);
  EXPECT_NEAR(smooth.Area(), 3.14159265 * a * b, 0.02 * 3.14159265 * a * b);
}

TEST(SilhouetteContour, KeepsHolesAndSeparateRegions) {
  cv::Mat mask = testing::EllipseMask(200, 150, 60, 75, 40, 50, 0.0);
  testing::EllipseMask(200, 150, 160, 75, 25, 25, 0.0, mask);
  // A hole in the first region.
  const cv::Mat hole = testing::EllipseMask(200, 150, 60, 75, 12, 15, 0.0);
  mask.setTo(0, hole);
  const SilhouetteContours contours = ExtractContours(mask);
  ASSERT_EQ(contours.polygons.size(), 2u);
  size_t holes = 0;
  for (const auto& p : contours.polygons) {
    holes += p.holes.size();
    for (const auto& h : p.holes)
      EXPECT_LT(RingArea(h), 0.0);
  }
  EXPECT_EQ(holes, 1u);
  // Point-in-contour agrees with the mask nearly everywhere (boundary pixels may differ).
  int disagree = 0;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      const bool inside =
          ContoursContain(contours, Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y)));
      if (inside != (mask.at<uint8_t>(y, x) != 0)) ++disagree;
    }
  }
  EXPECT_LT(disagree, 60);  // pixel centres within the simplification tolerance
}

TEST(ContourCodec, RoundTripsToAnEighthOfAPixel) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const cv::Mat mask = testing::RandomBlobMask(rng, 640, 480, 1 + trial % 4, trial % 2 == 0);
    const SilhouetteContours contours = ExtractContours(mask);
    const std::vector<uint8_t> bytes = EncodeContours(contours);
    SilhouetteContours decoded;
    std::string error;
    ASSERT_TRUE(DecodeContours(bytes, 640, 480, &decoded, &error)) << error;
    ASSERT_EQ(decoded.polygons.size(), contours.polygons.size());
    for (size_t p = 0; p < contours.polygons.size(); ++p) {
      ASSERT_EQ(decoded.polygons[p].outer.size(), contours.polygons[p].outer.size());
      ASSERT_EQ(decoded.polygons[p].holes.size(), contours.polygons[p].holes.size());
      for (size_t i = 0; i < contours.polygons[p].outer.size(); ++i) {
        EXPECT_LE(
            (decoded.polygons[p].outer[i] - contours.polygons[p].outer[i]).cwiseAbs().maxCoeff(),
            1.0f / 16.0f + 1e-5f);
      }
    }
  }
}

TEST(ContourCodec, RejectsCorruptAndRandomBytes) {
  const cv::Mat mask = testing::EllipseMask(100, 100, 50, 50, 30, 20, 0.2);
  const std::vector<uint8_t> good = EncodeContours(ExtractContours(mask));
  SilhouetteContours out;
  std::string error;
  for (size_t byte = 0; byte < good.size(); ++byte) {
    std::vector<uint8_t> bad = good;
    bad[byte] ^= 0x10;
    EXPECT_FALSE(DecodeContours(bad, 100, 100, &out, &error));
  }
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<uint8_t> bytes(rng() % 200);
    for (auto& b : bytes)
      b = static_cast<uint8_t>(rng());
    EXPECT_FALSE(DecodeContours(bytes, 640, 480, &out, &error));
  }
}

}  // namespace
}  // namespace silnet
