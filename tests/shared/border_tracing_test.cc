#include "shared/silhouette/border_tracing.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/silhouette/foreground_box.h"
#include "shared/util/check.h"

namespace silnet {
namespace {

// What the tracer must reproduce: OpenCV's own answer on the same box.
void ExpectSameAsOpenCv(const cv::Mat& mask, const cv::Rect& box, const std::string& what) {
  std::vector<std::vector<cv::Point>> expected, rings;
  std::vector<cv::Vec4i> expected_hierarchy, hierarchy;
  if (box.area() > 0) {
    cv::findContours(mask(box), expected, expected_hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE,
                     box.tl());
  }
  TraceBorders(mask, box, rings, hierarchy);
  ASSERT_EQ(rings.size(), expected.size()) << what;
  for (size_t i = 0; i < rings.size(); ++i)
    ASSERT_EQ(rings[i], expected[i]) << what << ", ring " << i;
  ASSERT_EQ(hierarchy, expected_hierarchy) << what;
}

// A mask of `kind`: filled ellipses with elliptic holes and islands in the holes, salt noise
// of any density (lone pixels, one pixel lines, pinches, holes of one pixel), or rings and
// lines drawn one pixel wide; pixels of any non-zero value.
cv::Mat RandomMask(std::mt19937& random, int kind, int width, int height) {
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random); };
  auto anywhere = [&] { return cv::Point(uniform(0, width - 1), uniform(0, height - 1)); };
  if (kind == 0) {
    for (int k = uniform(1, 4); k > 0; --k) {
      const cv::Point centre = anywhere();
      const int a = uniform(1, width / 2 + 1), b = uniform(1, height / 2 + 1);
      const double angle = uniform(0, 179);
      cv::ellipse(mask, centre, cv::Size(a, b), angle, 0, 360, uniform(1, 255), cv::FILLED);
      cv::ellipse(mask, centre, cv::Size(a / 2, b / 3), angle, 0, 360, 0, cv::FILLED);
      cv::ellipse(mask, centre, cv::Size(a / 5, b / 7), angle, 0, 360, 255, cv::FILLED);
    }
  } else if (kind == 1) {
    const int percent = uniform(2, 98);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (uniform(1, 100) <= percent)
          mask.at<uint8_t>(y, x) = static_cast<uint8_t>(uniform(1, 255));
      }
    }
  } else {
    for (int k = uniform(1, 6); k > 0; --k) {
      const int value = uniform(1, 255);
      if (k % 2 == 0) {
        cv::line(mask, anywhere(), anywhere(), value, 1, cv::LINE_8);
      } else {
        cv::circle(mask, anywhere(), uniform(0, 12), value, 1,
                   uniform(0, 1) == 0 ? cv::LINE_4 : cv::LINE_8);
      }
    }
  }
  return mask;
}

TEST(BorderTracingTest, SameRingsAndHierarchyAsOpenCvOnRandomMasks) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 3000; ++trial) {
    const int kind = trial % 3;
    // Noise stays small enough for the labels (larger noise goes to OpenCV, tested below).
    const int limit = kind == 1 ? 14 : 120;
    const int width = 1 + static_cast<int>(random() % limit),
              height = 1 + static_cast<int>(random() % limit);
    const cv::Mat mask = RandomMask(random, kind, width, height);
    const std::string what = "trial " + std::to_string(trial);
    ExpectSameAsOpenCv(mask, ForegroundBox(mask), what + ", foreground box");
    ExpectSameAsOpenCv(mask, cv::Rect(0, 0, width, height), what + ", whole mask");
    // A box that cuts the foreground, in a view of a larger image (a stride not its width).
    cv::Mat larger = cv::Mat::zeros(height + 3, width + 21, CV_8UC1);
    mask.copyTo(larger(cv::Rect(9, 1, width, height)));
    const cv::Mat view = larger(cv::Rect(9, 1, width, height));
    const cv::Rect inner(width / 4, height / 3, width - width / 4 - width / 5, height - height / 3);
    ExpectSameAsOpenCv(view, inner, what + ", inner box");
    if (HasFailure()) return;
  }
}

TEST(BorderTracingTest, MoreBordersThanLabelsGiveOpenCvsAnswerToo) {
  cv::Mat noise(70, 90, CV_8UC1);
  cv::randu(noise, 0, 256);
  const cv::Mat mask = noise > 180;  // hundreds of borders
  ExpectSameAsOpenCv(mask, cv::Rect(0, 0, mask.cols, mask.rows), "dense noise");
  cv::Mat dots = cv::Mat::zeros(40, 400, CV_8UC1);
  for (int x = 0; x < 400; x += 3)
    dots.at<uint8_t>(20, x) = 255;  // 134 lone pixels, one more than the labels
  ExpectSameAsOpenCv(dots, cv::Rect(0, 0, dots.cols, dots.rows), "lone pixels");
}

TEST(BorderTracingTest, EmptyBoxesAndBadInput) {
  std::vector<std::vector<cv::Point>> rings{{cv::Point(1, 1)}};
  std::vector<cv::Vec4i> hierarchy{cv::Vec4i(0, 0, 0, 0)};
  TraceBorders(cv::Mat::zeros(5, 5, CV_8UC1), cv::Rect(), rings, hierarchy);
  EXPECT_TRUE(rings.empty());
  EXPECT_TRUE(hierarchy.empty());
  EXPECT_THROW(TraceBorders(cv::Mat::zeros(5, 5, CV_8UC3), cv::Rect(0, 0, 5, 5), rings, hierarchy),
               CheckError);
  EXPECT_THROW(TraceBorders(cv::Mat::zeros(5, 5, CV_8UC1), cv::Rect(2, 2, 5, 5), rings, hierarchy),
               CheckError);
}

}  // namespace
}  // namespace silnet
