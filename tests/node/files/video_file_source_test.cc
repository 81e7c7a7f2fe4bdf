#include "node/capture/files/video_file_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "node/capture/frame_pacer.h"
#include "tests/support/temp_dir.h"

namespace silnet::node {
namespace {

using std::chrono::milliseconds;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr double kFps = 10.0;
constexpr int kFrames = 6;

// Smooth frames (JPEG keeps them well) that differ clearly from one another.
cv::Mat TestFrame(int k) {
  cv::Mat frame(kHeight, kWidth, CV_8UC3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      frame.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<uint8_t>(30 * k + x), static_cast<uint8_t>(40 + 2 * y),
                    static_cast<uint8_t>(200 - 25 * k));
    }
  }
  cv::rectangle(frame, cv::Rect(8 * k, 10, 12, 12), cv::Scalar(255, 255, 255), cv::FILLED);
  return frame;
}

double MeanAbsDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference);
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

// Writes kFrames TestFrame()s as a motion-JPEG AVI.
std::filesystem::path WriteTestVideo(const testing::TempDir& dir) {
  const std::filesystem::path path = dir / "clip.avi";
  cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), kFps,
                         cv::Size(kWidth, kHeight), true);
  EXPECT_TRUE(writer.isOpened()) << "OpenCV cannot write MJPG .avi here";
  for (int k = 0; k < kFrames; ++k)
    writer.write(TestFrame(k));
  writer.release();
  return path;
}

TEST(VideoFileSource, ReadsBackAnMjpgVideoFrameByFrame) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  VideoFileSource source(options);
  source.Open();
  EXPECT_EQ(source.Kind(), "video");
  EXPECT_EQ(source.Format().width, kWidth);
  EXPECT_EQ(source.Format().height, kHeight);
  EXPECT_DOUBLE_EQ(source.Format().fps, kFps);
  EXPECT_EQ(source.Format().pixel_format, "BGR");
  EXPECT_NE(source.Describe().find("MJPG"), std::string::npos) << source.Describe();

  for (int k = 0; k < kFrames; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame) << "frame " << k;
    EXPECT_EQ(frame.frame_index, static_cast<uint64_t>(k));
    ASSERT_EQ(frame.image.type(), CV_8UC3);
    ASSERT_EQ(frame.image.size(), cv::Size(kWidth, kHeight));
    EXPECT_LT(MeanAbsDifference(frame.image, TestFrame(k)), 4.0) << "frame " << k;
    if (k + 1 < kFrames) {
      EXPECT_GT(MeanAbsDifference(frame.image, TestFrame(k + 1)), 10.0) << "frame " << k;
    }
  }
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);
  EXPECT_EQ(source.Counters().frames, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(source.Counters().errors, 0u);
  source.Close();
  source.Close();
}

TEST(VideoFileSource, TimestampsFollowTheContainerFrameRate) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  options.start_ns = 1'000'000'000'000'000'000LL;
  VideoFileSource source(options);
  source.Open();
  for (int k = 0; k < kFrames; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
    EXPECT_EQ(frame.capture_time_ns, options.start_ns + k * 100'000'000LL);
  }
}

TEST(VideoFileSource, FrameRateOptionOverridesTheContainer) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  options.fps = 25.0;
  VideoFileSource source(options);
  source.Open();
  EXPECT_DOUBLE_EQ(source.Format().fps, 25.0);
}

TEST(VideoFileSource, FirstFrameAndFrameCountSelectARange) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  options.first_frame = 2;
  options.max_frames = 3;
  VideoFileSource source(options);
  source.Open();
  for (int k = 2; k < 5; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
    EXPECT_EQ(frame.frame_index, static_cast<uint64_t>(k));
    EXPECT_LT(MeanAbsDifference(frame.image, TestFrame(k)), 4.0) << "frame " << k;
  }
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);

  options.first_frame = kFrames + 3;
  options.max_frames = 0;
  VideoFileSource past_end(options);
  EXPECT_THROW(past_end.Open(), CaptureError);
}

TEST(VideoFileSource, WrongSizeFramesArePerFrameErrors) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  options.width = 32;
  options.height = 24;
  VideoFileSource source(options);
  source.Open();
  for (int k = 0; k < kFrames; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
    EXPECT_EQ(frame.frame_index, static_cast<uint64_t>(k));
    EXPECT_TRUE(frame.image.empty());
    EXPECT_NE(source.LastError().find("64x48, expected 32x24"), std::string::npos)
        << source.LastError();
  }
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);
  EXPECT_EQ(source.Counters().errors, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(source.Counters().dropped, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(source.Counters().frames, 0u);
}

TEST(VideoFileSource, PacedFramesAreNotReleasedBeforeTheirDueTime) {
  testing::TempDir dir;
  VideoFileSourceOptions options;
  options.file = WriteTestVideo(dir);
  options.fps = 50.0;
  options.real_time = true;
  options.start_ns = RealtimeNowNs() + 20'000'000;
  const FramePacer pacer(options.fps, options.start_ns);
  VideoFileSource source(options);
  source.Open();
  for (int k = 0; k < kFrames; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(5000)), CaptureStatus::kFrame);
    const int64_t released = RealtimeNowNs();
    EXPECT_EQ(frame.capture_time_ns, pacer.DueTimeNs(static_cast<uint64_t>(k)));
    EXPECT_GE(released, frame.capture_time_ns) << "frame " << k << " released early";
  }
}

TEST(VideoFileSource, UnopenableVideoThrowsNamingTheFile) {
  testing::TempDir dir;
  const std::filesystem::path missing = dir / "missing.avi";
  VideoFileSourceOptions options;
  options.file = missing;
  VideoFileSource missing_source(options);
  EXPECT_THAT([&] { missing_source.Open(); },
              ::testing::ThrowsMessage<CaptureError>(::testing::HasSubstr(missing.string())))
      << "Open() of a missing video";

  const std::filesystem::path garbage = dir / "garbage.avi";
  std::ofstream(garbage) << "this is not a video";
  options.file = garbage;
  VideoFileSource garbage_source(options);
  EXPECT_THAT([&] { garbage_source.Open(); },
              ::testing::ThrowsMessage<CaptureError>(::testing::HasSubstr(garbage.string())))
      << "Open() of a file that is not a video";
}

}  // namespace
}  // namespace silnet::node
