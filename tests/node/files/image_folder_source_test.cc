#include "node/capture/files/image_folder_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "node/capture/frame_pacer.h"
#include "tests/support/temp_dir.h"

namespace silnet::node {
namespace {

using std::chrono::milliseconds;

cv::Mat RandomImage(int rows, int cols, int type, uint64_t seed) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

void Write(const std::filesystem::path& path, const cv::Mat& image) {
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

// Reads everything up to kEndOfStream, failing on anything but kFrame.
std::vector<CapturedFrame> ReadAll(ImageFolderSource& source) {
  std::vector<CapturedFrame> frames;
  for (;;) {
    CapturedFrame frame;
    const CaptureStatus status = source.Read(&frame, milliseconds(1000));
    if (status == CaptureStatus::kEndOfStream) break;
    EXPECT_EQ(status, CaptureStatus::kFrame) << source.LastError();
    if (status != CaptureStatus::kFrame) break;
    frames.push_back(frame);
  }
  return frames;
}

TEST(ImageFolderSource, ReturnsTheImagesExactlyInNameOrder) {
  testing::TempDir dir;
  // Written out of order, with mixed extensions and files that are not images.
  const std::vector<std::string> names = {"a_000.png", "a_001.bmp", "a_002.PNG", "a_003.ppm",
                                          "a_004.tiff"};
  std::vector<cv::Mat> images;
  for (size_t i = 0; i < names.size(); ++i)
    images.push_back(RandomImage(24, 32, CV_8UC3, 100 + i));
  for (size_t i : {3, 0, 4, 2, 1})
    Write(dir / names[i], images[i]);
  std::ofstream(dir / "notes.txt") << "not an image";
  std::ofstream(dir / "a_001.png.bak") << "not an image either";
  std::filesystem::create_directory(dir / "a_0015.png");  // a folder, not a file

  ImageFolderSourceOptions options;
  options.folder = dir.path();
  ImageFolderSource source(options);
  source.Open();
  EXPECT_EQ(source.Kind(), "images");
  EXPECT_EQ(source.Format().width, 32);
  EXPECT_EQ(source.Format().height, 24);
  EXPECT_EQ(source.Format().pixel_format, "BGR");
  ASSERT_EQ(source.Files().size(), names.size());

  const std::vector<CapturedFrame> frames = ReadAll(source);
  ASSERT_EQ(frames.size(), names.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(source.Files()[i].filename().string(), names[i]);
    EXPECT_EQ(frames[i].frame_index, i);
    EXPECT_EQ(frames[i].image.type(), CV_8UC3);
    EXPECT_TRUE(SameImage(frames[i].image, images[i])) << "frame " << i;
  }
  CapturedFrame after;
  EXPECT_EQ(source.Read(&after, milliseconds(0)), CaptureStatus::kEndOfStream);
  EXPECT_EQ(source.Counters().frames, names.size());
  EXPECT_EQ(source.Counters().errors, 0u);
  EXPECT_EQ(source.Counters().dropped, 0u);
  source.Close();
  source.Close();
}

TEST(ImageFolderSource, MaskModeYieldsGreyscale) {
  testing::TempDir dir;
  std::vector<cv::Mat> masks;
  for (int i = 0; i < 3; ++i) {
    cv::Mat mask = RandomImage(20, 30, CV_8UC1, 7 + i) > 128;
    masks.push_back(mask);
    Write(dir / ("m" + std::to_string(i) + ".png"), mask);
  }
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.masks = true;
  ImageFolderSource source(options);
  source.Open();
  EXPECT_EQ(source.Format().pixel_format, "GRAY");
  const std::vector<CapturedFrame> frames = ReadAll(source);
  ASSERT_EQ(frames.size(), masks.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].image.type(), CV_8UC1);
    EXPECT_TRUE(SameImage(frames[i].image, masks[i])) << "mask " << i;
  }
}

TEST(ImageFolderSource, ColourImagesReadInMaskModeAreGreyscale) {
  testing::TempDir dir;
  Write(dir / "0.png", RandomImage(10, 12, CV_8UC3, 1));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.masks = true;
  ImageFolderSource source(options);
  source.Open();
  CapturedFrame frame;
  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
  EXPECT_EQ(frame.image.type(), CV_8UC1);
  EXPECT_EQ(frame.image.size(), cv::Size(12, 10));
}

TEST(ImageFolderSource, WrongSizeAndCorruptImagesArePerFrameErrors) {
  testing::TempDir dir;
  std::vector<cv::Mat> images;
  for (int i = 0; i < 6; ++i)
    images.push_back(RandomImage(24, 32, CV_8UC3, 50 + i));
  Write(dir / "000000.png", images[0]);
  Write(dir / "000001.png", images[1]);
  Write(dir / "000002.png", RandomImage(8, 16, CV_8UC3, 3));      // wrong size
  std::ofstream(dir / "000003.png") << "this is not a png file";  // corrupt
  Write(dir / "000004.png", images[4]);
  std::ofstream(dir / "000005.jpg") << "";  // empty
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  ImageFolderSource source(options);
  source.Open();

  CapturedFrame frame;
  for (uint64_t i : {0, 1}) {
    ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
    EXPECT_EQ(frame.frame_index, i);
    EXPECT_TRUE(SameImage(frame.image, images[i]));
  }

  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 2u);
  EXPECT_TRUE(frame.image.empty());
  EXPECT_NE(source.LastError().find("000002.png"), std::string::npos) << source.LastError();
  EXPECT_NE(source.LastError().find("16x8"), std::string::npos) << source.LastError();
  EXPECT_NE(source.LastError().find("32x24"), std::string::npos) << source.LastError();

  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 3u);
  EXPECT_TRUE(frame.image.empty());
  EXPECT_NE(source.LastError().find("000003.png"), std::string::npos) << source.LastError();

  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 4u);
  EXPECT_TRUE(SameImage(frame.image, images[4]));

  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 5u);
  EXPECT_NE(source.LastError().find("000005.jpg"), std::string::npos) << source.LastError();

  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);
  EXPECT_EQ(source.Counters().frames, 3u);
  EXPECT_EQ(source.Counters().errors, 3u);
  EXPECT_EQ(source.Counters().dropped, 3u);
}

TEST(ImageFolderSource, CorruptFirstImageDoesNotHideTheSize) {
  testing::TempDir dir;
  std::ofstream(dir / "0.png") << "garbage";
  const cv::Mat image = RandomImage(6, 9, CV_8UC3, 2);
  Write(dir / "1.png", image);
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  ImageFolderSource source(options);
  source.Open();
  EXPECT_EQ(source.Format().width, 9);
  EXPECT_EQ(source.Format().height, 6);
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 0u);
  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 1u);
  EXPECT_TRUE(SameImage(frame.image, image));
}

TEST(ImageFolderSource, ExpectedSizeOptionRejectsOtherSizes) {
  testing::TempDir dir;
  const cv::Mat right = RandomImage(12, 16, CV_8UC3, 4);
  Write(dir / "0.png", RandomImage(24, 32, CV_8UC3, 3));
  Write(dir / "1.png", right);
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.width = 16;
  options.height = 12;
  ImageFolderSource source(options);
  source.Open();
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 0u);
  EXPECT_NE(source.LastError().find("32x24, expected 16x12"), std::string::npos)
      << source.LastError();
  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
  EXPECT_TRUE(SameImage(frame.image, right));
}

TEST(ImageFolderSource, FirstFrameAndFrameCountSelectARange) {
  testing::TempDir dir;
  std::vector<cv::Mat> images;
  for (int i = 0; i < 5; ++i) {
    images.push_back(RandomImage(4, 4, CV_8UC3, 30 + i));
    Write(dir / (std::to_string(i) + ".png"), images.back());
  }
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.first_frame = 1;
  options.max_frames = 3;
  ImageFolderSource source(options);
  source.Open();
  const std::vector<CapturedFrame> frames = ReadAll(source);
  ASSERT_EQ(frames.size(), 3u);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].frame_index, i + 1);
    EXPECT_TRUE(SameImage(frames[i].image, images[i + 1]));
  }

  options.first_frame = 5;
  ImageFolderSource past_end(options);
  EXPECT_THROW(past_end.Open(), CaptureError);
}

TEST(ImageFolderSource, MissingOrEmptyFolderThrowsNamingThePath) {
  testing::TempDir dir;
  const std::filesystem::path missing = dir / "no-such-folder";
  ImageFolderSourceOptions options;
  options.folder = missing;
  ImageFolderSource missing_source(options);
  EXPECT_THAT([&] { missing_source.Open(); },
              ::testing::ThrowsMessage<CaptureError>(::testing::HasSubstr(missing.string())))
      << "Open() of a missing folder";

  const std::filesystem::path empty = dir / "empty";
  std::filesystem::create_directory(empty);
  std::ofstream(empty / "readme.txt") << "no images here";
  options.folder = empty;
  ImageFolderSource empty_source(options);
  EXPECT_THAT([&] { empty_source.Open(); },
              ::testing::ThrowsMessage<CaptureError>(::testing::HasSubstr(empty.string())))
      << "Open() of a folder without images";
}

TEST(ImageFolderSource, UnpacedTimestampsFollowTheFrameRate) {
  testing::TempDir dir;
  for (int i = 0; i < 4; ++i)
    Write(dir / (std::to_string(i) + ".png"), RandomImage(4, 4, CV_8UC3, i));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.fps = 10.0;
  options.start_ns = 1'000'000'000'000'000'000LL;
  options.first_frame = 1;
  ImageFolderSource source(options);
  source.Open();
  const std::vector<CapturedFrame> frames = ReadAll(source);
  ASSERT_EQ(frames.size(), 3u);
  for (size_t n = 0; n < frames.size(); ++n)
    EXPECT_EQ(frames[n].capture_time_ns, options.start_ns + static_cast<int64_t>(n) * 100'000'000);
}

TEST(ImageFolderSource, UnpacedTimestampsWithoutFrameRateAreTheReadTime) {
  testing::TempDir dir;
  Write(dir / "0.png", RandomImage(4, 4, CV_8UC3, 0));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  ImageFolderSource source(options);
  source.Open();
  const int64_t before = RealtimeNowNs();
  CapturedFrame frame;
  ASSERT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kFrame);
  EXPECT_GE(frame.capture_time_ns, before);
  EXPECT_LE(frame.capture_time_ns, RealtimeNowNs());
}

TEST(ImageFolderSource, PacedFramesAreNotReleasedBeforeTheirDueTime) {
  testing::TempDir dir;
  for (int i = 0; i < 4; ++i)
    Write(dir / (std::to_string(i) + ".png"), RandomImage(4, 4, CV_8UC3, i));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.fps = 20.0;
  options.real_time = true;
  options.start_ns = RealtimeNowNs() + 30'000'000;
  options.offset_frames = 1.5;
  const FramePacer pacer(options.fps, options.start_ns, options.offset_frames);
  ImageFolderSource source(options);
  source.Open();
  for (uint64_t k = 0; k < 4; ++k) {
    CapturedFrame frame;
    ASSERT_EQ(source.Read(&frame, milliseconds(5000)), CaptureStatus::kFrame);
    const int64_t released = RealtimeNowNs();
    EXPECT_EQ(frame.frame_index, k);
    EXPECT_EQ(frame.capture_time_ns, pacer.DueTimeNs(k));
    EXPECT_GE(released, pacer.DueTimeNs(k)) << "frame " << k << " released early";
  }
  CapturedFrame frame;
  EXPECT_EQ(source.Read(&frame, milliseconds(0)), CaptureStatus::kEndOfStream);
}

TEST(ImageFolderSource, PacedReadTimesOutBeforeTheDueTimeAndKeepsTheFrame) {
  testing::TempDir dir;
  Write(dir / "0.png", RandomImage(4, 4, CV_8UC3, 0));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.fps = 10.0;
  options.real_time = true;
  options.start_ns = RealtimeNowNs() + 300'000'000;
  ImageFolderSource source(options);
  source.Open();
  CapturedFrame frame;
  const int64_t before = RealtimeNowNs();
  EXPECT_EQ(source.Read(&frame, milliseconds(20)), CaptureStatus::kTimeout);
  EXPECT_GE(RealtimeNowNs() - before, 20'000'000);
  ASSERT_EQ(source.Read(&frame, milliseconds(5000)), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 0u);
  EXPECT_GE(RealtimeNowNs(), options.start_ns);
  EXPECT_EQ(source.Counters().frames, 1u);
}

TEST(ImageFolderSource, RealTimeWithoutFrameRateIsRejected) {
  testing::TempDir dir;
  Write(dir / "0.png", RandomImage(4, 4, CV_8UC3, 0));
  ImageFolderSourceOptions options;
  options.folder = dir.path();
  options.real_time = true;
  ImageFolderSource source(options);
  EXPECT_THROW(source.Open(), CaptureError);
}

}  // namespace
}  // namespace silnet::node
