#include "aggregator/hulls/silhouette_source.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "shared/silhouette/silhouette_contour.h"

namespace silnet::aggregator {
namespace {

TEST(RasteriseContours, GivesBackTheMaskTheContoursWereExtractedFrom) {
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::ellipse(mask, {120, 120}, {80, 60}, 20, 0, 360, 255, cv::FILLED);
  cv::circle(mask, {110, 120}, 25, 0, cv::FILLED);              // a hole
  cv::circle(mask, {110, 120}, 8, 255, cv::FILLED);             // an island inside it
  cv::rectangle(mask, {250, 20}, {300, 200}, 255, cv::FILLED);  // a second region
  const cv::Mat back = RasteriseContours(ExtractContours(mask), mask.cols, mask.rows);
  ASSERT_EQ(back.size(), mask.size());
  cv::Mat differ;
  cv::bitwise_xor(mask, back, differ);
  const int area = cv::countNonZero(mask);
  const int wrong = cv::countNonZero(differ);
  // Contours simplified at 0.5 px: only boundary pixels may flip, far under 2 % of the area.
  EXPECT_LT(wrong, area / 50) << wrong << " of " << area;
  EXPECT_EQ(back.at<uint8_t>(120, 110), 255);  // the island
  EXPECT_EQ(back.at<uint8_t>(120, 125), 0);    // the hole
  EXPECT_EQ(back.at<uint8_t>(100, 275), 255);  // the second region
}

}  // namespace
}  // namespace silnet::aggregator
