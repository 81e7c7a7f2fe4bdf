#include "shared/silhouette/douglas_peucker.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/util/check.h"

namespace silnet {
namespace {

// OpenCV's answer, or nothing where it throws.
bool OpenCvSimplification(const std::vector<cv::Point2f>& ring, double tolerance,
                          std::vector<cv::Point2f>& out) {
  try {
    cv::approxPolyDP(ring, out, tolerance, true);
    return true;
  } catch (const cv::Exception&) {
    return false;
  }
}

void ExpectSameAsOpenCv(const std::vector<cv::Point2f>& ring, double tolerance,
                        const std::string& what) {
  std::vector<cv::Point2f> expected;
  if (!OpenCvSimplification(ring, tolerance, expected)) {
    EXPECT_THROW(SimplifyClosedRing(ring, tolerance), CheckError) << what;
    return;
  }
  const std::vector<cv::Point2f> simplified = SimplifyClosedRing(ring, tolerance);
  ASSERT_EQ(simplified.size(), expected.size()) << what;
  for (size_t i = 0; i < simplified.size(); ++i) {
    // Bit for bit: the same points, not merely close ones.
    ASSERT_EQ(simplified[i].x, expected[i].x) << what << ", point " << i;
    ASSERT_EQ(simplified[i].y, expected[i].y) << what << ", point " << i;
  }
}

// The rings contour extraction simplifies: traced outlines of random blobs and noise,
// pushed half a pixel out and smoothed, so points lie off the pixel lattice.
std::vector<std::vector<cv::Point2f>> TracedRings(std::mt19937& random) {
  const int width = 8 + static_cast<int>(random() % 120),
            height = 8 + static_cast<int>(random() % 120);
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  for (int k = 0; k < 4; ++k) {
    const cv::Point centre(static_cast<int>(random() % width), static_cast<int>(random() % height));
    cv::ellipse(mask, centre,
                cv::Size(1 + static_cast<int>(random() % 40), 1 + static_cast<int>(random() % 40)),
                static_cast<double>(random() % 180), 0, 360, 255, cv::FILLED);
  }
  std::vector<std::vector<cv::Point>> traced;
  cv::findContours(mask, traced, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  std::vector<std::vector<cv::Point2f>> rings;
  for (const auto& t : traced) {
    const size_t n = t.size();
    std::vector<cv::Point2f> ring(n);
    for (size_t i = 0; i < n; ++i) {
      const cv::Point2f before(t[(i + n - 1) % n]), here(t[i]), after(t[(i + 1) % n]);
      ring[i] = 0.25f * (before + after) + 0.5f * here + cv::Point2f(0.1f, -0.3f);
    }
    rings.push_back(ring);
  }
  return rings;
}

TEST(DouglasPeuckerTest, SamePointsAsOpenCvOnTracedOutlines) {
  std::mt19937 random(3);
  for (int trial = 0; trial < 300; ++trial) {
    for (const std::vector<cv::Point2f>& ring : TracedRings(random)) {
      for (const double tolerance : {0.0, 0.3, 0.6, 1.0, 2.5, 12.0}) {
        ExpectSameAsOpenCv(ring, tolerance,
                           "trial " + std::to_string(trial) + ", " + std::to_string(ring.size()) +
                               " points, tolerance " + std::to_string(tolerance));
        if (HasFailure()) return;
      }
    }
  }
}

TEST(DouglasPeuckerTest, SamePointsAsOpenCvOnRandomAndDegenerateRings) {
  std::mt19937 random(9);
  std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
  std::uniform_int_distribution<int> lattice(0, 3);
  for (int trial = 0; trial < 2000; ++trial) {
    const size_t n = 1 + random() % 40;
    std::vector<cv::Point2f> ring(n);
    for (cv::Point2f& p : ring) {
      // Every third trial on a coarse lattice: repeated points, collinear runs, equal chords.
      p = trial % 3 == 0 ? cv::Point2f(static_cast<float>(lattice(random)),
                                       static_cast<float>(lattice(random)))
                         : cv::Point2f(coordinate(random), coordinate(random));
    }
    for (const double tolerance : {0.0, 0.5, 3.0, 40.0})
      ExpectSameAsOpenCv(ring, tolerance, "random trial " + std::to_string(trial));
    if (HasFailure()) return;
  }
  EXPECT_TRUE(SimplifyClosedRing({}, 1.0).empty());
  EXPECT_THROW(SimplifyClosedRing({cv::Point2f(0, 0)}, -1.0), CheckError);
}

}  // namespace
}  // namespace silnet
