#include "node/capture/source_factory.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet::node {
namespace {

TEST(SourceFactory, ParsesDescriptionsAndRejectsOthers) {
  EXPECT_EQ(ParseSourceDescription("v4l2:/dev/video2").location, "/dev/video2");
  EXPECT_TRUE(ParseSourceDescription("sim-masks:/d/cam00").masks());
  EXPECT_EQ(ParseSourceDescription("libcamera:").kind, "libcamera");
  for (const char* bad : {"", "video", "webcam:/dev/video0", "images:", ":x"}) {
    EXPECT_THROW(ParseSourceDescription(bad), InputError) << bad;
  }
}

TEST(SourceFactory, ASimulatedCameraReplaysItsFramesAtItsRateAndOffset) {
  testing::TempDir dir;
  const DatasetLayout layout(dir.path());
  std::filesystem::create_directories(layout.MasksDir("camA"));
  for (int k = 0; k < 3; ++k) {
    cv::imwrite(layout.MaskPath("camA", k).string(), cv::Mat(24, 32, CV_8U, cv::Scalar(k * 50)));
  }
  CameraModel camera;
  camera.id = "camA";
  camera.width = 32;
  camera.height = 24;
  camera.fps = 20.0;
  camera.time_offset = 2.0;
  SaveCalibration(layout.GroundTruthPath(), {camera});
  SourceOptions options;
  options.start_ns = 1'000'000'000;  // long past: frames are due at once
  options.speed = 2.0;
  auto source = MakeCaptureSource(
      ParseSourceDescription("sim-masks:" + (dir / "camA").string() + "/"), options);
  source->Open();
  EXPECT_EQ(source->Kind(), "sim");
  EXPECT_DOUBLE_EQ(source->Format().fps, 40.0);
  CapturedFrame frame;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(source->Read(&frame, std::chrono::milliseconds(100)), CaptureStatus::kFrame);
    EXPECT_EQ(frame.image.type(), CV_8UC1);
    EXPECT_EQ(frame.frame_index, static_cast<uint64_t>(k));
    // Frame k is due at start + (k + offset) / fps.
    EXPECT_EQ(frame.capture_time_ns, 1'000'000'000 + static_cast<int64_t>((k + 2.0) / 40.0 * 1e9));
  }
  EXPECT_EQ(source->Read(&frame, std::chrono::milliseconds(10)), CaptureStatus::kEndOfStream);
  EXPECT_THROW(MakeCaptureSource(ParseSourceDescription("sim:" + (dir / "camB").string()), options),
               InputError);
}

}  // namespace
}  // namespace silnet::node
