#include "aggregator/hulls/silhouette_interpolation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

// Exact disc: pixels whose centre lies within `radius` of `centre`.
cv::Mat Disc(cv::Size size, const cv::Point2d& centre, double radius) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      if (std::hypot(x - centre.x, y - centre.y) <= radius) mask.at<uint8_t>(y, x) = 255;
    }
  }
  return mask;
}

double IntersectionOverUnion(const cv::Mat& a, const cv::Mat& b) {
  return static_cast<double>(cv::countNonZero(a & b)) / cv::countNonZero(a | b);
}

TEST(SilhouetteInterpolationTest, SignedDistanceHasTheDocumentedSigns) {
  const cv::Mat disc = Disc({120, 100}, {60, 50}, 20);
  const cv::Mat sd = SignedDistanceMap(disc);
  for (int y = 0; y < disc.rows; ++y) {
    for (int x = 0; x < disc.cols; ++x) {
      if (disc.at<uint8_t>(y, x)) {
        ASSERT_GE(sd.at<float>(y, x), 0.5f);
      } else {
        ASSERT_LE(sd.at<float>(y, x), -0.5f);
      }
    }
  }
  // Centre of the disc: about 20 px from the outline.
  EXPECT_NEAR(sd.at<float>(50, 60), 20.0f, 1.0f);
  EXPECT_NEAR(sd.at<float>(50, 5), -(55.0f - 20.0f), 1.0f);
}

TEST(SilhouetteInterpolationTest, EndpointsReproduceTheFrames) {
  const cv::Mat a = Disc({160, 120}, {60, 60}, 25), b = Disc({160, 120}, {90, 55}, 30);
  EXPECT_EQ(cv::countNonZero(InterpolateSilhouette(a, b, 0.0) != a), 0);
  EXPECT_EQ(cv::countNonZero(InterpolateSilhouette(a, b, 1.0) != b), 0);
}

TEST(SilhouetteInterpolationTest, MovingDiscFollowsTheBlendedDistanceField) {
  // For two discs of radius r the blended field is r - (1 - f)|x - c0| - f|x - c1|: the
  // result is the ellipse with foci c0, c1 and (1 - f)|x - c0| + f|x - c1| < r, which lies
  // inside the disc at the blended centre (triangle inequality). Outside a one-pixel band
  // at its outline the interpolation must match it exactly.
  const cv::Size size(200, 160);
  const cv::Point2d c0(70, 80), c1(110, 86);
  const double radius = 35;
  const cv::Mat a = Disc(size, c0, radius), b = Disc(size, c1, radius);
  for (double f : {0.25, 0.5, 0.75}) {
    const cv::Mat mid = InterpolateSilhouette(a, b, f);
    size_t wrong = 0;
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const double blend =
            (1 - f) * std::hypot(x - c0.x, y - c0.y) + f * std::hypot(x - c1.x, y - c1.y);
        if (std::abs(blend - radius) <= 1.0) continue;
        if ((mid.at<uint8_t>(y, x) != 0) != (blend < radius)) ++wrong;
      }
    }
    EXPECT_EQ(wrong, 0u) << "f = " << f;
    // Closer to the disc at the true intermediate position than the nearer frame is.
    const cv::Mat truth = Disc(size, c0 + f * (c1 - c0), radius);
    EXPECT_GT(IntersectionOverUnion(mid, truth),
              IntersectionOverUnion(f < 0.5 ? a : b, truth) + 0.05)
        << "f = " << f;
  }
}

TEST(SilhouetteInterpolationTest, GrowingDiscHasTheBlendedRadius) {
  // Concentric discs: sd_f(x) = r_f - |x| exactly, so the result is the disc of radius r_f
  // up to one pixel of distance-transform and sampling error at the outline.
  const cv::Size size(160, 160);
  const cv::Point2d centre(80, 78);
  const cv::Mat a = Disc(size, centre, 20), b = Disc(size, centre, 50);
  const double f = 0.4, radius = 20 + f * 30;
  const cv::Mat mid = InterpolateSilhouette(a, b, f);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const double r = std::hypot(x - centre.x, y - centre.y);
      if (std::abs(r - radius) <= 1.0) continue;
      ASSERT_EQ(mid.at<uint8_t>(y, x) != 0, r < radius) << x << ", " << y;
    }
  }
}

TEST(SilhouetteInterpolationTest, EmptyFrameFallsBackToTheNearerFrame) {
  const cv::Mat a = Disc({64, 48}, {30, 20}, 10), empty = cv::Mat::zeros(48, 64, CV_8UC1);
  EXPECT_EQ(cv::countNonZero(InterpolateSilhouette(a, empty, 0.3) != a), 0);
  EXPECT_EQ(cv::countNonZero(InterpolateSilhouette(a, empty, 0.7)), 0);
}

}  // namespace
}  // namespace silnet::aggregator
