#include "node/pipeline/frame_processor.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "shared/silhouette/contour_codec.h"
#include "shared/silhouette/hull_codec.h"
#include "silnet.h"

namespace silnet::node {
namespace {

FrameProcessorOptions MaskOptions(int contour_every = 1) {
  FrameProcessorOptions o;
  o.camera_id = "cam07";
  o.session = 42;
  o.segmentation.method = SegmentationMethod::kMaskInput;
  o.segmentation.min_blob_area = 20;
  o.contour_every = contour_every;
  return o;
}

CapturedFrame Frame(const cv::Mat& image, uint64_t index) {
  CapturedFrame f;
  f.image = image;
  f.frame_index = index;
  f.capture_time_ns = 1000 + static_cast<int64_t>(index);
  return f;
}

TEST(FrameProcessor, EncodesTheSilhouetteHullAndContourWithTheFrameHeader) {
  FrameProcessor processor(MaskOptions(), 160, 120);
  cv::Mat mask(120, 160, CV_8U, cv::Scalar(0));
  cv::ellipse(mask, {80, 60}, {30, 20}, 10, 0, 360, 255, -1);
  const ProcessedFrame out = processor.Process(Frame(mask, 5));
  EXPECT_EQ(out.hull.camera_id, "cam07");
  EXPECT_EQ(out.hull.session, 42u);
  EXPECT_EQ(out.hull.frame_index, 5u);
  EXPECT_EQ(out.hull.capture_time_ns, 1005);
  EXPECT_EQ(out.hull.flags, 0u);
  HullPayload decoded;
  std::string error;
  ASSERT_TRUE(DecodeHull(out.hull.payload, 160, 120, &decoded, &error)) << error;
  const SilhouetteHull expected = ComputeSilhouetteHull(mask);
  ASSERT_EQ(decoded.hull.size(), expected.size());
  for (int i = 0; i < expected.size(); ++i)
    EXPECT_EQ(decoded.hull.vertex(i), expected.vertex(i));
  EXPECT_EQ(decoded.foreground_pixels, cv::countNonZero(mask));
  ASSERT_TRUE(out.contour.has_value());
  SilhouetteContours contours;
  ASSERT_TRUE(DecodeContours(out.contour->payload, 160, 120, &contours, &error)) << error;
  EXPECT_EQ(contours.polygons.size(), 1u);
}

TEST(FrameProcessor, FlagsEmptyClippedSeveralBlobsSaturatedAndBadFrames) {
  FrameProcessor processor(MaskOptions(), 160, 120);
  cv::Mat empty(120, 160, CV_8U, cv::Scalar(0));
  EXPECT_TRUE(processor.Process(Frame(empty, 0)).hull.flags & silnet_wire_FRAME_EMPTY);
  cv::Mat clipped = empty.clone();
  cv::rectangle(clipped, cv::Rect(0, 40, 30, 30), 255, -1);
  EXPECT_TRUE(processor.Process(Frame(clipped, 1)).hull.flags & silnet_wire_FRAME_CLIPPED);
  cv::Mat two = empty.clone();
  cv::rectangle(two, cv::Rect(20, 20, 20, 20), 255, -1);
  cv::rectangle(two, cv::Rect(100, 60, 20, 20), 255, -1);
  EXPECT_TRUE(processor.Process(Frame(two, 2)).hull.flags & silnet_wire_FRAME_MULTIPLE_BLOBS);
  cv::Mat full(120, 160, CV_8U, cv::Scalar(255));
  EXPECT_TRUE(processor.Process(Frame(full, 3)).hull.flags & silnet_wire_FRAME_SATURATED);
  const ProcessedFrame wrong = processor.Process(Frame(cv::Mat(60, 80, CV_8U, cv::Scalar(255)), 4));
  EXPECT_TRUE(wrong.hull.flags & silnet_wire_FRAME_BAD_INPUT);
  EXPECT_FALSE(wrong.contour.has_value());
  const ProcessedFrame dropped = processor.Flagged(9, 77, silnet_wire_FRAME_DROPPED);
  EXPECT_TRUE(dropped.hull.flags & silnet_wire_FRAME_DROPPED);
  EXPECT_EQ(dropped.hull.frame_index, 9u);
  HullPayload decoded;
  std::string error;
  EXPECT_TRUE(DecodeHull(dropped.hull.payload, 160, 120, &decoded, &error));
  EXPECT_TRUE(decoded.hull.empty());
}

TEST(FrameProcessor, ContoursAtTheConfiguredRateAndSettingsByName) {
  FrameProcessor processor(MaskOptions(3), 160, 120);
  cv::Mat mask(120, 160, CV_8U, cv::Scalar(0));
  cv::circle(mask, {80, 60}, 20, 255, -1);
  int contours = 0;
  for (uint64_t k = 0; k < 9; ++k)
    contours += processor.Process(Frame(mask, k)).contour ? 1 : 0;
  EXPECT_EQ(contours, 3);
  std::string error;
  EXPECT_TRUE(processor.SetParameter("contour_every", "0", &error)) << error;
  EXPECT_FALSE(processor.Process(Frame(mask, 9)).contour.has_value());
  EXPECT_TRUE(processor.SetParameter("min_blob_area", "500", &error)) << error;
  EXPECT_EQ(processor.options().segmentation.min_blob_area, 500);
  EXPECT_FALSE(processor.SetParameter("min_blob_area", "-3", &error));
  EXPECT_FALSE(processor.SetParameter("nonsense", "1", &error));
  EXPECT_NE(error.find("nonsense"), std::string::npos);
  EXPECT_THROW(FrameProcessor(MaskOptions(), 0, 10), InputError);
}

}  // namespace
}  // namespace silnet::node
