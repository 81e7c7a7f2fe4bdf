// The live job's in-memory contours for its hull batches (aggregator/live).

#include "aggregator/live/recent_contours.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/silhouette/contour_codec.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr int kWidth = 160, kHeight = 120;

// A Contour record of a disc whose centre moves with the frame index.
FrameRecord DiscRecord(const std::string& camera, uint32_t session, uint64_t index) {
  cv::Mat mask = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  cv::circle(mask, {40 + static_cast<int>(index % 60), 60}, 25, cv::Scalar(255), cv::FILLED);
  FrameRecord r;
  r.camera_id = camera;
  r.session = session;
  r.frame_index = index;
  r.width = kWidth;
  r.height = kHeight;
  r.payload = EncodeContours(ExtractContours(mask));
  return r;
}

CameraModel Camera(const std::string& id) {
  CameraModel camera;
  camera.id = id;
  camera.width = kWidth;
  camera.height = kHeight;
  return camera;
}

TEST(RecentContours, GivesTheMasksOfTheRecordsItHolds) {
  RecentContours contours("store");
  for (uint64_t k = 0; k < 20; ++k)
    contours.Add(DiscRecord("cam00", 2, k));
  EXPECT_EQ(contours.CameraIds(), std::vector<std::string>{"cam00"});
  EXPECT_EQ(contours.FrameCount("cam00"), 20);
  EXPECT_EQ(contours.FrameCount("cam01"), 0);
  const FrameRecord record = DiscRecord("cam00", 2, 7);
  const cv::Mat expected = ContourRecordMask(record, Camera("cam00"), "expected");
  const cv::Mat mask = contours.Mask(Camera("cam00"), 7);
  EXPECT_EQ(cv::countNonZero(mask != expected), 0);
  EXPECT_GT(cv::countNonZero(mask), 1500);  // a disc of radius 25 px: ~1960 px
  EXPECT_THROW(contours.Mask(Camera("cam00"), 20), InputError);
  EXPECT_THROW(contours.Mask(Camera("cam01"), 3), InputError);
  CameraModel wrong = Camera("cam00");
  wrong.width = 320;
  EXPECT_THROW(contours.Mask(wrong, 7), InputError);  // not the calibration's size
}

TEST(RecentContours, FloorsPerCameraSessionsAndClosing) {
  RecentContours contours("store");
  EXPECT_FALSE(contours.Holds("cam00", 0));
  for (uint64_t k = 0; k < 50; ++k) {
    contours.Add(DiscRecord("cam00", 3, k));
    if (k >= 10) contours.Add(DiscRecord("cam01", 3, k));  // followed from frame 10
  }
  EXPECT_TRUE(contours.Holds("cam00", 0));
  EXPECT_FALSE(contours.Holds("cam01", 5));
  EXPECT_TRUE(contours.Holds("cam01", 10));

  contours.DropBefore("cam00", 30);  // each camera its own floor
  contours.DropBefore("cam01", 25);
  EXPECT_EQ(contours.size(), 20u + 25u);
  EXPECT_FALSE(contours.Holds("cam00", 29));
  EXPECT_TRUE(contours.Holds("cam00", 30));
  EXPECT_TRUE(contours.Holds("cam01", 25));
  EXPECT_THROW(contours.Mask(Camera("cam00"), 29), InputError);
  contours.Add(DiscRecord("cam00", 3, 12));  // below the floor (a late resend): not kept
  EXPECT_EQ(contours.size(), 45u);
  contours.DropBefore("cam00", 20);  // a floor never goes back
  EXPECT_FALSE(contours.Holds("cam00", 25));

  contours.Add(DiscRecord("cam00", 2, 60));  // an older session: ignored
  contours.Add(DiscRecord("cam01", 4, 3));   // a restarted node: its old session goes
  EXPECT_EQ(contours.size(), 20u + 1u);
  EXPECT_TRUE(contours.Holds("cam01", 3));
  EXPECT_EQ(contours.FrameCount("cam01"), 4);

  contours.Close();
  contours.Add(DiscRecord("cam00", 3, 50));
  EXPECT_EQ(contours.size(), 0u);
  EXPECT_FALSE(contours.Holds("cam00", 50));
}

}  // namespace
}  // namespace silnet::aggregator
