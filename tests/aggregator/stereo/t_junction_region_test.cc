// T-junction corners of silhouettes and the true-surface region they define.

#include "aggregator/stereo/t_junction_region.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// True if some corner lies within `tolerance` px of (x, y).
bool HasCornerNear(const std::vector<cv::Point>& corners, int x, int y, int tolerance = 2) {
  for (const cv::Point& c : corners) {
    if (std::abs(c.x - x) <= tolerance && std::abs(c.y - y) <= tolerance) return true;
  }
  return false;
}

TEST(InwardOutlineCorners, FindsTheInwardCornersOfATAndNoneOfADisc) {
  // A "T": bar x 20..79, y 20..39; stem x 40..59, y 40..89. Inward corners where the stem
  // meets the bar, at about (40, 40) and (59, 40); the six outer corners turn outward.
  cv::Mat t = cv::Mat::zeros(110, 100, CV_8UC1);
  cv::rectangle(t, cv::Rect(20, 20, 60, 20), 255, cv::FILLED);
  cv::rectangle(t, cv::Rect(40, 40, 20, 50), 255, cv::FILLED);
  const std::vector<cv::Point> corners = InwardOutlineCorners(t, {});
  EXPECT_EQ(corners.size(), 2u);
  EXPECT_TRUE(HasCornerNear(corners, 40, 40));
  EXPECT_TRUE(HasCornerNear(corners, 59, 40));

  cv::Mat disc = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::circle(disc, cv::Point(50, 50), 30, 255, cv::FILLED);
  EXPECT_TRUE(InwardOutlineCorners(disc, {}).empty());

  // A hole's outline counts too: a square hole has four inward corners.
  cv::Mat frame = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::rectangle(frame, cv::Rect(10, 10, 80, 80), 255, cv::FILLED);
  cv::rectangle(frame, cv::Rect(35, 35, 30, 30), 0, cv::FILLED);
  EXPECT_EQ(InwardOutlineCorners(frame, {}).size(), 4u);

  TJunctionOptions bad;
  bad.arm_px = 1;
  EXPECT_THROW(InwardOutlineCorners(t, bad), CheckError);
}

TEST(TJunctionRegion, KeepsRimPointsNearACorner) {
  CameraModel camera;
  camera.width = 100;
  camera.height = 110;
  camera.K << 100, 0, 50, 0, 100, 55, 0, 0, 1;  // at the origin looking down +z
  cv::Mat t = cv::Mat::zeros(110, 100, CV_8UC1);
  cv::rectangle(t, cv::Rect(20, 20, 60, 20), 255, cv::FILLED);
  cv::rectangle(t, cv::Rect(40, 40, 20, 50), 255, cv::FILLED);
  // Points at depth 1 projecting to a corner (40, 40) and far from it (50, 80); normals along
  // the ray (facing the camera) or across it (on the rim).
  const Eigen::Vector3d at_corner(-0.1, -0.15, 1.0), far(0.0, 0.25, 1.0);
  const Eigen::Vector3d facing(0, 0, -1), across(1, 0, 0);
  const std::vector<Eigen::Vector3d> points = {at_corner, at_corner, far, far};
  const std::vector<Eigen::Vector3d> normals = {across, facing, across, facing};
  const std::vector<uint8_t> region = TJunctionRegion(points, normals, {camera}, {t});
  EXPECT_EQ(region, (std::vector<uint8_t>{1, 0, 0, 0}));
}

}  // namespace
}  // namespace silnet::aggregator
