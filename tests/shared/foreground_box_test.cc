#include "shared/silhouette/foreground_box.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "shared/util/check.h"

namespace silnet {
namespace {

// Random blobs, lone pixels at the borders and rows, widths that are not multiples of eight
// (or of the 64-byte blocks scanned at once),
// and views into larger images: the same box as OpenCV's full scan.
TEST(ForegroundBoxTest, MatchesOpenCvsBoundingRectOnRandomMasks) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> size(1, 300);
  for (int trial = 0; trial < 400; ++trial) {
    const int width = size(random), height = size(random);
    cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
    const int kind = trial % 4;
    if (kind == 0) {  // a few ellipses
      for (int k = 0; k < 3; ++k) {
        const cv::Point centre(static_cast<int>(random() % width),
                               static_cast<int>(random() % height));
        const cv::Size axes(1 + static_cast<int>(random() % 12),
                            1 + static_cast<int>(random() % 12));
        cv::ellipse(mask, centre, axes, 0, 0, 360, 255, cv::FILLED);
      }
    } else if (kind == 1) {  // lone pixels of any non-zero value
      for (int k = 0; k < 1 + trial % 5; ++k)
        mask.at<uint8_t>(static_cast<int>(random() % height), static_cast<int>(random() % width)) =
            static_cast<uint8_t>(1 + random() % 255);
    } else if (kind == 2) {  // a pixel on each border
      mask.at<uint8_t>(0, static_cast<int>(random() % width)) = 1;
      mask.at<uint8_t>(static_cast<int>(random() % height), width - 1) = 255;
    }  // kind 3: empty
    EXPECT_EQ(ForegroundBox(mask), cv::boundingRect(mask))
        << width << "x" << height << " trial " << trial;
    // The same mask as a view into a larger image (a stride that is not its width).
    cv::Mat larger = cv::Mat::zeros(height + 4, width + 13, CV_8UC1);
    mask.copyTo(larger(cv::Rect(5, 2, width, height)));
    const cv::Mat view = larger(cv::Rect(5, 2, width, height));
    // (Against the continuous mask's box: OpenCV 4.6's own answer on such views can be wrong.)
    EXPECT_EQ(ForegroundBox(view), cv::boundingRect(mask)) << "view, trial " << trial;
  }
}

TEST(ForegroundBoxTest, RejectsOtherTypes) {
  EXPECT_THROW(ForegroundBox(cv::Mat::zeros(4, 4, CV_8UC3)), CheckError);
  EXPECT_EQ(ForegroundBox(cv::Mat()), cv::Rect());
}

}  // namespace
}  // namespace silnet
