// CleanMask fills holes only: background that reaches the frame's border around the
// foreground (a U's opening, a C's mouth) is never filled, wherever the shape sits and however
// narrow its box, and real holes smaller than the limit are.

#include "node/segmentation/mask_cleanup.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace silnet::node {
namespace {

// Pixels of `before`'s background that are 4-connected to the frame's border and `after`
// made foreground.
int FilledOpenBackground(const cv::Mat& before, const cv::Mat& after) {
  cv::Mat background = before == 0, labels;
  const int components = cv::connectedComponents(background, labels, 4, CV_32S);
  int filled = 0;
  std::vector<uint8_t> open(static_cast<size_t>(components), 0);
  for (int y = 0; y < before.rows; ++y) {
    for (int x = 0; x < before.cols; ++x) {
      const bool border = x == 0 || y == 0 || x == before.cols - 1 || y == before.rows - 1;
      if (border && background.at<uint8_t>(y, x))
        open[static_cast<size_t>(labels.at<int>(y, x))] = 1;
    }
  }
  for (int y = 0; y < before.rows; ++y) {
    for (int x = 0; x < before.cols; ++x) {
      if (background.at<uint8_t>(y, x) && open[static_cast<size_t>(labels.at<int>(y, x))] &&
          after.at<uint8_t>(y, x) != 0)
        ++filled;
    }
  }
  return filled;
}

TEST(MaskCleanupTest, FillsHolesButNeverOpenBackground) {
  SegmentationOptions options;
  options.open_radius = 0;
  options.close_radius = 0;
  options.min_blob_area = 10;
  options.max_hole_area = 400;
  int shapes = 0;
  for (int width = 4; width <= 40; ++width) {
    for (int x0 = 1; x0 < 12; ++x0) {
      // A U: two legs and a base, its opening (the gap between the legs) up to the top row.
      cv::Mat mask = cv::Mat::zeros(48, 64, CV_8UC1);
      const int leg = std::max(1, width / 4);
      cv::rectangle(mask, cv::Rect(x0, 0, leg, 30), 255, cv::FILLED);
      cv::rectangle(mask, cv::Rect(x0 + width - leg, 0, leg, 30), 255, cv::FILLED);
      cv::rectangle(mask, cv::Rect(x0, 26, width, 4), 255, cv::FILLED);
      // and a closed ring below it with a hole of 4 pixels.
      cv::rectangle(mask, cv::Rect(x0, 36, 6, 6), 255, cv::FILLED);
      cv::rectangle(mask, cv::Rect(x0 + 2, 38, 2, 2), 0, cv::FILLED);
      const cv::Mat before = mask.clone();
      const CleanupStats stats = CleanMask(&mask, options);
      EXPECT_EQ(FilledOpenBackground(before, mask), 0) << "width " << width << " at " << x0;
      EXPECT_EQ(stats.holes_filled, 1) << "width " << width << " at " << x0;
      EXPECT_EQ(mask.at<uint8_t>(38, x0 + 2), 255) << "width " << width << " at " << x0;
      ++shapes;
    }
  }
  EXPECT_EQ(shapes, 37 * 11);
}

}  // namespace
}  // namespace silnet::node
