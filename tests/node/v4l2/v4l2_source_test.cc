#include "node/capture/v4l2/v4l2_source.h"

#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <poll.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <future>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "node/capture/source_factory.h"
#include "tests/node/v4l2/fake_v4l2_device.h"
#include "tests/support/eventually.h"

namespace silnet::node {
namespace {

using std::chrono::milliseconds;
using Kind = FakeV4l2Step::Kind;

// Success if `text` contains `part`.
::testing::AssertionResult HasText(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

// The BGR colour of a YUV sample by the BT.601 video-range equations (not through OpenCV).
cv::Vec3b Bt601(const FakeYuv& sample) {
  const double y = 1.164 * (sample.y - 16);
  const double u = sample.u - 128;
  const double v = sample.v - 128;
  return cv::Vec3b(cv::saturate_cast<uint8_t>(y + 2.018 * u),
                   cv::saturate_cast<uint8_t>(y - 0.813 * v - 0.391 * u),
                   cv::saturate_cast<uint8_t>(y + 1.596 * v));
}

// Largest channel difference between `image` and the YUYV pattern of `tick` in BGR.
int YuyvPatternError(const cv::Mat& image, uint64_t tick) {
  int worst = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b expected = Bt601(FakeYuyvPixel(x, y, tick));
      const cv::Vec3b got = image.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(got[c] - expected[c]));
    }
  }
  return worst;
}

// PSNR of `image` against the Motion-JPEG pattern of `tick`.
double MjpegPatternPsnr(const cv::Mat& image, uint64_t tick) {
  return cv::PSNR(image, FakeBgrPattern(image.cols, image.rows, tick));
}

// A source reading from a fake the test keeps inspecting.
struct Rig {
  std::shared_ptr<FakeV4l2Device> fake;
  std::unique_ptr<V4l2Source> source;
};

// A source over a fake that follows `config`.
Rig MakeRig(FakeV4l2Config config, V4l2SourceOptions options) {
  Rig rig;
  rig.fake = std::make_shared<FakeV4l2Device>(std::move(config));
  rig.source = std::make_unique<V4l2Source>(std::move(options), FakeV4l2Device::Handle(rig.fake));
  return rig;
}

// 64x48 at 30 fps in `format`, re-opening without delay.
V4l2SourceOptions SmallOptions(V4l2PixelFormat format = V4l2PixelFormat::kYuyv) {
  V4l2SourceOptions options;
  options.width = 64;
  options.height = 48;
  options.fps = 30.0;
  options.pixel_format = format;
  options.reopen_interval = milliseconds(0);
  return options;
}

// `count` good frames in a row.
std::vector<FakeV4l2Step> Frames(int count) {
  return std::vector<FakeV4l2Step>(static_cast<size_t>(count), FakeV4l2Step::Frame());
}

// One Read() with a short timeout (the fake never waits).
CaptureStatus ReadOnce(V4l2Source& source, CapturedFrame* frame) {
  return source.Read(frame, milliseconds(10));
}

// The message of the CaptureError Open() throws ("" if it throws none).
std::string OpenError(V4l2Source& source) {
  try {
    source.Open();
  } catch (const CaptureError& e) {
    return e.what();
  }
  return "";
}

// The source used the device correctly and never left the driver without buffers.
void ExpectCleanProtocol(const FakeV4l2Device& fake) {
  EXPECT_TRUE(fake.violations().empty()) << ::testing::PrintToString(fake.violations());
  EXPECT_EQ(fake.starved_frames(), 0u);
}

TEST(V4l2Source, DeliversYuyvFramesAsTheKnownPattern) {
  FakeV4l2Config config;
  config.line_padding = 16;
  config.script = Frames(6);
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  EXPECT_EQ(rig.source->Kind(), "v4l2");
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 64x48 YUYV 30 fps");
  const CaptureFormat format = rig.source->Format();
  EXPECT_EQ(format.width, 64);
  EXPECT_EQ(format.height, 48);
  EXPECT_DOUBLE_EQ(format.fps, 30.0);
  EXPECT_EQ(format.pixel_format, "YUYV");

  std::vector<cv::Mat> images;
  for (uint64_t i = 0; i < 6; ++i) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame) << rig.source->LastError();
    EXPECT_EQ(frame.frame_index, i);
    ASSERT_EQ(frame.image.type(), CV_8UC3);
    ASSERT_EQ(frame.image.size(), cv::Size(64, 48));
    EXPECT_LE(YuyvPatternError(frame.image, i), 2) << "frame " << i;
    images.push_back(frame.image);
  }
  // The images own their pixels: buffers the driver refilled since did not change them.
  for (uint64_t i = 0; i < images.size(); ++i)
    EXPECT_LE(YuyvPatternError(images[i], i), 2);

  CapturedFrame frame;
  EXPECT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kTimeout);
  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.frames, 6u);
  EXPECT_EQ(counters.dropped, 0u);
  EXPECT_EQ(counters.errors, 0u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, DecodesMjpegFramesOfVaryingLength) {
  FakeV4l2Config config;
  config.script = Frames(6);
  V4l2SourceOptions options = SmallOptions(V4l2PixelFormat::kMjpeg);
  options.width = 160;
  options.height = 120;
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().pixel_format, "MJPG");
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 160x120 MJPG 30 fps");

  for (uint64_t i = 0; i < 6; ++i) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame) << rig.source->LastError();
    EXPECT_EQ(frame.frame_index, i);
    ASSERT_EQ(frame.image.size(), cv::Size(160, 120));
    EXPECT_GT(MjpegPatternPsnr(frame.image, i), 30.0) << "frame " << i;
    EXPECT_LT(MjpegPatternPsnr(frame.image, i + 1), 25.0) << "frame " << i;
  }
  const auto& deliveries = rig.fake->deliveries();
  ASSERT_EQ(deliveries.size(), 6u);
  EXPECT_NE(deliveries[0].bytesused, deliveries[1].bytesused);
  EXPECT_LT(deliveries[0].bytesused, 160u * 120u * 2u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, UsesTheSizeAndRateTheDriverGranted) {
  FakeV4l2Config config;
  config.forced_size = cv::Size(320, 240);
  config.max_fps[V4L2_PIX_FMT_YUYV] = 25.0;
  config.script = Frames(3);
  V4l2SourceOptions options = SmallOptions();
  options.width = 1280;
  options.height = 720;
  options.fps = 60.0;
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  const CaptureFormat format = rig.source->Format();
  EXPECT_EQ(format.width, 320);
  EXPECT_EQ(format.height, 240);
  EXPECT_DOUBLE_EQ(format.fps, 25.0);
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 320x240 YUYV 25 fps");

  std::vector<int64_t> times;
  for (uint64_t i = 0; i < 3; ++i) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame) << rig.source->LastError();
    ASSERT_EQ(frame.image.size(), cv::Size(320, 240));
    EXPECT_LE(YuyvPatternError(frame.image, i), 2);
    times.push_back(frame.capture_time_ns);
  }
  EXPECT_NEAR(static_cast<double>(times[1] - times[0]), 40e6, 1e6);
  EXPECT_NEAR(static_cast<double>(times[2] - times[1]), 40e6, 1e6);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, AutoFormatPrefersYuyvAtTheAskedRate) {
  FakeV4l2Config config;
  config.script = Frames(1);
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kAuto));
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().pixel_format, "YUYV");
  EXPECT_EQ(rig.fake->pixel_format(), V4L2_PIX_FMT_YUYV);
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_LE(YuyvPatternError(frame.image, 0), 2);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, AutoFormatTakesMjpegWhenYuyvIsSlower) {
  FakeV4l2Config config;
  config.max_fps = {{V4L2_PIX_FMT_YUYV, 10.0}, {V4L2_PIX_FMT_MJPEG, 30.0}};
  config.script = Frames(1);
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kAuto));
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().pixel_format, "MJPG");
  EXPECT_DOUBLE_EQ(rig.source->Format().fps, 30.0);
  EXPECT_EQ(rig.fake->pixel_format(), V4L2_PIX_FMT_MJPEG);
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_GT(MjpegPatternPsnr(frame.image, 0), 30.0);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, AutoFormatReturnsToYuyvWhenMjpegIsNoFaster) {
  FakeV4l2Config config;
  config.max_fps = {{V4L2_PIX_FMT_YUYV, 15.0}, {V4L2_PIX_FMT_MJPEG, 15.0}};
  config.script = Frames(1);
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kAuto));
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().pixel_format, "YUYV");
  EXPECT_DOUBLE_EQ(rig.source->Format().fps, 15.0);
  EXPECT_EQ(rig.fake->pixel_format(), V4L2_PIX_FMT_YUYV);
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_LE(YuyvPatternError(frame.image, 0), 2);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, UsesThePixelFormatTheDriverChoseInstead) {
  FakeV4l2Config config;
  config.pixel_formats = {V4L2_PIX_FMT_MJPEG};
  config.script = Frames(1);
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kYuyv));
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().pixel_format, "MJPG");
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_GT(MjpegPatternPsnr(frame.image, 0), 30.0);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, RejectsADeviceOfferingNeitherYuyvNorMjpeg) {
  FakeV4l2Config config;
  config.pixel_formats = {V4L2_PIX_FMT_NV12};
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kAuto));
  const std::string error = OpenError(*rig.source);
  EXPECT_TRUE(HasText(error, "/dev/video0"));
  EXPECT_TRUE(HasText(error, "neither YUYV nor Motion-JPEG"));
  EXPECT_TRUE(HasText(error, "NV12"));
  EXPECT_EQ(rig.fake->open_descriptors(), 0u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, SequenceGapsBecomeDroppedFramesAndIndexJumps) {
  FakeV4l2Config config;
  config.first_sequence = 57;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Frame(), FakeV4l2Step::Frame(3),
                   FakeV4l2Step::Frame(), FakeV4l2Step::Frame(1)};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  const std::vector<uint64_t> expected = {0, 1, 5, 6, 8};
  for (const uint64_t index : expected) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
    EXPECT_EQ(frame.frame_index, index);
    EXPECT_LE(YuyvPatternError(frame.image, index), 2);
  }
  EXPECT_EQ(rig.source->Counters().frames, 5u);
  EXPECT_EQ(rig.source->Counters().dropped, 4u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, SequenceNumbersWrapAround) {
  FakeV4l2Config config;
  config.first_sequence = 0xFFFFFFFEu;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Frame(), FakeV4l2Step::Frame(1),
                   FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  for (const uint64_t index : {0u, 1u, 3u, 4u}) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
    EXPECT_EQ(frame.frame_index, index);
  }
  EXPECT_EQ(rig.source->Counters().dropped, 1u);
}

TEST(V4l2Source, ErrorFlaggedBuffersGiveFrameErrorsWithTheirIndex) {
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Frame(2), FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 0u);

  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 1u);
  EXPECT_TRUE(frame.image.empty());
  EXPECT_NE(frame.capture_time_ns, 0);
  EXPECT_TRUE(HasText(rig.source->LastError(), "/dev/video0"));
  EXPECT_TRUE(HasText(rig.source->LastError(), "frame 1"));

  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 4u);
  EXPECT_LE(YuyvPatternError(frame.image, 4), 2);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 5u);
  EXPECT_TRUE(frame.image.empty());
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 6u);

  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.frames, 3u);
  EXPECT_EQ(counters.errors, 2u);
  EXPECT_EQ(counters.dropped, 4u);  // two error frames and the gap of two
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, CorruptAndTruncatedJpegGiveFrameErrorsWithTheirIndex) {
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Bad(Kind::kCorruptJpeg),
                   FakeV4l2Step::Bad(Kind::kTruncatedJpeg), FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions(V4l2PixelFormat::kMjpeg));
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  for (const uint64_t index : {1u, 2u}) {
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrameError);
    EXPECT_EQ(frame.frame_index, index);
    EXPECT_TRUE(frame.image.empty());
    EXPECT_TRUE(HasText(rig.source->LastError(), "corrupt Motion-JPEG"));
  }
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 3u);
  EXPECT_GT(MjpegPatternPsnr(frame.image, 3), 30.0);
  EXPECT_EQ(rig.source->Counters().errors, 2u);
  EXPECT_EQ(rig.source->Counters().dropped, 2u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, ShortYuyvFrameGivesAFrameError) {
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Bad(Kind::kTruncatedJpeg),
                   FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrameError);
  EXPECT_EQ(frame.frame_index, 1u);
  EXPECT_TRUE(HasText(rig.source->LastError(), "short frame"));
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 2u);
  ExpectCleanProtocol(*rig.fake);
}

// Device loss through POLLERR (0), or DQBUF failing with ENODEV or EIO.
class V4l2SourceLossTest : public ::testing::TestWithParam<int> {};

TEST_P(V4l2SourceLossTest, DisappearingDeviceIsReopenedAndTheIndexJumpsForward) {
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Frame(),
                   FakeV4l2Step::Frame(), FakeV4l2Step::Disappear(GetParam(), 2, 10),
                   FakeV4l2Step::Frame(), FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  CapturedFrame frame;
  for (uint64_t i = 0; i < 3; ++i) {
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
    EXPECT_EQ(frame.frame_index, i);
  }

  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kError);
  EXPECT_TRUE(frame.image.empty());
  EXPECT_EQ(frame.capture_time_ns, 0);
  EXPECT_TRUE(HasText(rig.source->LastError(), "/dev/video0"));
  EXPECT_TRUE(HasText(rig.source->LastError(), "device lost"));
  EXPECT_EQ(rig.fake->open_descriptors(), 0u);
  EXPECT_EQ(rig.fake->mappings(), 0u);

  EXPECT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kTimeout);
  EXPECT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kTimeout);
  EXPECT_EQ(rig.fake->open_attempts(), 3);
  EXPECT_EQ(rig.source->Counters().reopens, 0u);

  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame) << rig.source->LastError();
  EXPECT_EQ(frame.frame_index, 13u);  // 2 + the 11 frame periods since frame 2
  EXPECT_LE(YuyvPatternError(frame.image, 13), 2);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 14u);

  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.frames, 5u);
  EXPECT_EQ(counters.errors, 1u);
  EXPECT_EQ(counters.reopens, 1u);
  EXPECT_EQ(counters.dropped, 10u);
  EXPECT_EQ(rig.fake->open_attempts(), 4);
  EXPECT_EQ(rig.fake->streamon_calls(), 2);
  EXPECT_EQ(rig.fake->open_descriptors(), 1u);
  ExpectCleanProtocol(*rig.fake);
}

INSTANTIATE_TEST_SUITE_P(LossKinds, V4l2SourceLossTest, ::testing::Values(0, ENODEV, EIO),
                         [](const ::testing::TestParamInfo<int>& loss) {
                           return loss.param == 0        ? std::string("PollError")
                                  : loss.param == ENODEV ? std::string("Enodev")
                                                         : std::string("Eio");
                         });

TEST(V4l2Source, ReopenIsTriedAtMostOncePerInterval) {
  using Clock = std::chrono::steady_clock;
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Disappear(0, 1, 5), FakeV4l2Step::Frame()};
  V4l2SourceOptions options = SmallOptions();
  options.reopen_interval = milliseconds(150);
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(rig.source->Read(&frame, milliseconds(0)), CaptureStatus::kFrame);

  const Clock::time_point start = Clock::now();
  ASSERT_EQ(rig.source->Read(&frame, milliseconds(0)), CaptureStatus::kError);
  EXPECT_EQ(rig.fake->open_attempts(), 1);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(rig.source->Read(&frame, milliseconds(0)), CaptureStatus::kTimeout);
  EXPECT_EQ(rig.fake->open_attempts(), 1);

  // Waits for the interval, tries once (the device is not back yet).
  EXPECT_EQ(rig.source->Read(&frame, milliseconds(1000)), CaptureStatus::kTimeout);
  EXPECT_GE(Clock::now() - start, milliseconds(150));
  EXPECT_EQ(rig.fake->open_attempts(), 2);
  EXPECT_EQ(rig.source->Read(&frame, milliseconds(0)), CaptureStatus::kTimeout);
  EXPECT_EQ(rig.fake->open_attempts(), 2);

  ASSERT_EQ(rig.source->Read(&frame, milliseconds(1000)), CaptureStatus::kFrame);
  EXPECT_GE(Clock::now() - start, milliseconds(300));
  EXPECT_EQ(rig.fake->open_attempts(), 3);
  EXPECT_EQ(frame.frame_index, 6u);
  EXPECT_EQ(rig.source->Counters().reopens, 1u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, OpenFailuresThrowCaptureErrorNamingTheDevice) {
  {
    FakeV4l2Config config;
    V4l2SourceOptions options = SmallOptions();
    options.device = "/dev/video7";
    Rig rig = MakeRig(config, options);
    const std::string error = OpenError(*rig.source);
    EXPECT_TRUE(HasText(error, "/dev/video7"));
    EXPECT_TRUE(HasText(error, "No such file or directory"));
  }
  {
    FakeV4l2Config config;
    config.open_errno = EACCES;
    Rig rig = MakeRig(config, SmallOptions());
    const std::string error = OpenError(*rig.source);
    EXPECT_TRUE(HasText(error, "/dev/video0"));
    EXPECT_TRUE(HasText(error, "Permission denied"));
  }
  {
    FakeV4l2Config config;
    config.open_errno = EBUSY;
    Rig rig = MakeRig(config, SmallOptions());
    const std::string error = OpenError(*rig.source);
    EXPECT_TRUE(HasText(error, "/dev/video0"));
    EXPECT_TRUE(HasText(error, "busy"));
  }
}

TEST(V4l2Source, RejectsDevicesThatCannotStreamVideoCapture) {
  struct Case {
    uint32_t capabilities;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING, "is not a video capture device"},
      {V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING, "multi-planar"},
      {V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE, "does not support streaming I/O"},
  };
  for (const Case& c : cases) {
    FakeV4l2Config config;
    config.capabilities = c.capabilities;
    Rig rig = MakeRig(config, SmallOptions());
    const std::string error = OpenError(*rig.source);
    EXPECT_TRUE(HasText(error, "/dev/video0"));
    EXPECT_TRUE(HasText(error, c.reason));
    EXPECT_EQ(rig.fake->open_descriptors(), 0u);
    ExpectCleanProtocol(*rig.fake);
  }
}

TEST(V4l2Source, SystemDeviceRejectsNodesThatAreNoCameras) {
  V4l2SourceOptions options = SmallOptions();
  options.device = "/dev/null";
  V4l2Source not_v4l2(options);
  const std::string error = OpenError(not_v4l2);
  EXPECT_TRUE(HasText(error, "/dev/null"));
  EXPECT_TRUE(HasText(error, "not a V4L2 device"));

  options.device = "/nonexistent/silnet-video0";
  V4l2Source missing(options);
  const std::string missing_error = OpenError(missing);
  EXPECT_TRUE(HasText(missing_error, "/nonexistent/silnet-video0"));
  EXPECT_TRUE(HasText(missing_error, "cannot open"));
}

// The CaptureError a V4l2Source constructed with `options` throws ("" if none).
std::string ConstructionError(V4l2SourceOptions options) {
  try {
    V4l2Source source(std::move(options),
                      FakeV4l2Device::Handle(std::make_shared<FakeV4l2Device>(FakeV4l2Config{})));
  } catch (const CaptureError& e) {
    return e.what();
  }
  return "";
}

TEST(V4l2Source, RejectsBadOptionsNamingTheDevice) {
  V4l2SourceOptions options = SmallOptions();
  options.width = 0;
  EXPECT_TRUE(HasText(ConstructionError(options), "/dev/video0"));
  options = SmallOptions();
  options.fps = -1.0;
  EXPECT_TRUE(HasText(ConstructionError(options), "frame rate"));
  options = SmallOptions();
  options.buffer_count = 0;
  EXPECT_TRUE(HasText(ConstructionError(options), "buffer count"));
}

TEST(V4l2Source, BuffersAreAlwaysRequeuedOverALongScript) {
  for (const uint32_t max_buffers : {8u, 2u}) {
    SCOPED_TRACE(max_buffers);
    FakeV4l2Config config;
    config.max_buffers = max_buffers;
    for (int i = 0; i < 3000; ++i) {
      if (i % 50 == 25) {
        config.script.push_back(FakeV4l2Step::NoFrame());
      } else if (i % 7 == 3) {
        config.script.push_back(FakeV4l2Step::Bad(Kind::kErrorFrame));
      } else if (i % 13 == 5) {
        config.script.push_back(FakeV4l2Step::Frame(2));
      } else {
        config.script.push_back(FakeV4l2Step::Frame());
      }
    }
    V4l2SourceOptions options = SmallOptions();
    options.width = 32;
    options.height = 24;
    Rig rig = MakeRig(config, options);
    rig.source->Open();

    uint64_t frames = 0;
    uint64_t errors = 0;
    uint64_t last_index = 0;
    for (int guard = 0; guard < 10000; ++guard) {
      CapturedFrame frame;
      const CaptureStatus status = rig.source->Read(&frame, milliseconds(0));
      if (status == CaptureStatus::kTimeout) {
        if (rig.fake->steps_left() == 0) break;
        continue;
      }
      ASSERT_NE(status, CaptureStatus::kEndOfStream);
      ASSERT_FALSE(rig.fake->deliveries().empty());
      const uint64_t tick = rig.fake->deliveries().back().tick;
      ASSERT_EQ(frame.frame_index, tick);
      if (frames + errors > 0) {
        ASSERT_GT(frame.frame_index, last_index);
      }
      last_index = frame.frame_index;
      if (status == CaptureStatus::kFrame) {
        ++frames;
        ASSERT_LE(YuyvPatternError(frame.image, tick), 2);
      } else {
        ++errors;
        ASSERT_TRUE(frame.image.empty());
      }
    }
    EXPECT_EQ(rig.fake->steps_left(), 0u);
    const CaptureCounters counters = rig.source->Counters();
    EXPECT_EQ(counters.frames, frames);
    EXPECT_EQ(counters.errors, errors);
    EXPECT_GT(frames, 2000u);
    EXPECT_EQ(counters.frames + counters.dropped, last_index + 1);
    EXPECT_EQ(rig.fake->buffers_with_driver(), rig.fake->allocated_buffers());
    EXPECT_EQ(rig.fake->allocated_buffers(), std::min<size_t>(4, max_buffers));
    ExpectCleanProtocol(*rig.fake);
  }
}

TEST(V4l2Source, CloseIsIdempotentAndReleasesTheDevice) {
  FakeV4l2Config config;
  config.script = Frames(4);
  Rig rig = MakeRig(config, SmallOptions());
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 (not open)");
  rig.source->Close();  // before Open: nothing to do
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);

  rig.source->Close();
  EXPECT_FALSE(rig.fake->streaming());
  EXPECT_EQ(rig.fake->streamoff_calls(), 1);
  EXPECT_EQ(rig.fake->mappings(), 0u);
  EXPECT_EQ(rig.fake->allocated_buffers(), 0u);
  EXPECT_EQ(rig.fake->open_descriptors(), 0u);
  rig.source->Close();
  EXPECT_EQ(rig.fake->streamoff_calls(), 1);
  EXPECT_THROW(ReadOnce(*rig.source, &frame), CheckError);

  // Open() starts over; the destructor closes.
  rig.source->Open();
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 0u);
  EXPECT_EQ(rig.fake->open_descriptors(), 1u);
  rig.source.reset();
  EXPECT_EQ(rig.fake->open_descriptors(), 0u);
  EXPECT_EQ(rig.fake->mappings(), 0u);
  EXPECT_EQ(rig.fake->streamoff_calls(), 2);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, TimesOutWhenNoFrameArrives) {
  FakeV4l2Config config;
  config.script = {FakeV4l2Step::NoFrame(), FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  CapturedFrame frame;
  EXPECT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kTimeout);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 0u);
  EXPECT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kTimeout);
  EXPECT_EQ(rig.source->Counters().errors, 0u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2Source, MovesMonotonicDriverTimestampsToRealtime) {
  FakeV4l2Config config;
  config.script = Frames(3);
  const int64_t before = RealtimeNowNs();
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  std::vector<int64_t> times;
  for (int i = 0; i < 3; ++i) {
    CapturedFrame frame;
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
    times.push_back(frame.capture_time_ns);
  }
  // The fake's tick 0 is the CLOCK_MONOTONIC instant it was made.
  EXPECT_NEAR(static_cast<double>(times[0] - before), 0.0, 50e6);
  EXPECT_NEAR(static_cast<double>(times[1] - times[0]), 1e9 / 30.0, 1e5);
  EXPECT_NEAR(static_cast<double>(times[2] - times[1]), 1e9 / 30.0, 1e5);
}

TEST(V4l2Source, UsesTheReadTimeWithoutMonotonicTimestamps) {
  FakeV4l2Config config;
  config.monotonic_timestamps = false;
  config.script = Frames(2);
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  for (int i = 0; i < 2; ++i) {
    CapturedFrame frame;
    const int64_t before = RealtimeNowNs();
    ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
    const int64_t after = RealtimeNowNs();
    EXPECT_GE(frame.capture_time_ns, before);
    EXPECT_LE(frame.capture_time_ns, after);
  }
}

TEST(V4l2Source, RateIsUnknownWithoutFrameRateControl) {
  FakeV4l2Config config;
  config.supports_frame_rate = false;
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Frame(1)};
  Rig rig = MakeRig(config, SmallOptions());
  rig.source->Open();
  EXPECT_EQ(rig.source->Format().fps, 0.0);
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 64x48 YUYV fps unknown");
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 2u);
  ExpectCleanProtocol(*rig.fake);
}

// --- Full-resolution stills ---

using Clock = std::chrono::steady_clock;

// Checks `condition` every millisecond for up to a minute (generous for a busy machine); true
// once it holds (testing::Eventually).
bool WaitUntil(const std::function<bool()>& condition) {
  return testing::Eventually(condition, std::chrono::seconds(60), milliseconds(1));
}

// A camera whose video is 64x48: YUYV goes up to 160x120, Motion-JPEG to 320x240 (4:3, the
// still) and to 432x240 (larger, but 9:5).
FakeV4l2Config StillCamera() {
  FakeV4l2Config config;
  config.frame_sizes[V4L2_PIX_FMT_YUYV] = {FakeFrameSizes::Discrete(64, 48),
                                           FakeFrameSizes::Discrete(160, 120)};
  config.frame_sizes[V4L2_PIX_FMT_MJPEG] = {
      FakeFrameSizes::Discrete(64, 48), FakeFrameSizes::Discrete(160, 120),
      FakeFrameSizes::Discrete(320, 240), FakeFrameSizes::Discrete(432, 240)};
  return config;
}

// SmallOptions() with a still timeout no busy machine reaches.
V4l2SourceOptions StillOptions() {
  V4l2SourceOptions options = SmallOptions();
  options.still_timeout = milliseconds(120000);
  return options;
}

// What a TakeStill() call gave.
struct StillOutcome {
  std::optional<StillPhoto> still;
  std::string error;  // the CaptureError's message; "" if none
};

StillOutcome CallTakeStill(V4l2Source& source) {
  StillOutcome outcome;
  try {
    outcome.still = source.TakeStill(CapturedFrame{});
  } catch (const CaptureError& e) {
    outcome.error = e.what();
  }
  return outcome;
}

// A still taken by TakeStill() on another thread and served by one Read() on this one.
struct ServedStill {
  StillOutcome outcome;
  CaptureStatus status = CaptureStatus::kTimeout;  // of the Read() that served it
  CapturedFrame frame;                             // of that Read()
};

ServedStill TakeStillServedByRead(V4l2Source& source) {
  std::future<StillOutcome> taking =
      std::async(std::launch::async, [&source] { return CallTakeStill(source); });
  const bool requested = WaitUntil([&] {
    return source.StillRequested() || taking.wait_for(milliseconds(0)) == std::future_status::ready;
  });
  EXPECT_TRUE(requested);
  ServedStill served;
  served.status = source.Read(&served.frame, milliseconds(10));
  served.outcome = taking.get();
  return served;
}

// The deliveries of frames of `size`.
std::vector<FakeV4l2Delivery> DeliveriesOfSize(const FakeV4l2Device& fake, cv::Size size) {
  std::vector<FakeV4l2Delivery> found;
  for (const FakeV4l2Delivery& delivery : fake.deliveries()) {
    if (delivery.size == size) found.push_back(delivery);
  }
  return found;
}

TEST(V4l2SourceStill, TakesTheLargestSameAspectSizeWhileAnotherThreadReads) {
  FakeV4l2Config config = StillCamera();
  config.max_fps[V4L2_PIX_FMT_MJPEG] = 15.0;  // the switch lowers the rate; it must come back
  config.streamon_periods = 2;
  config.frames_after_script = true;
  Rig rig = MakeRig(config, StillOptions());
  rig.source->Open();

  // What the reading thread saw of each Read().
  struct Seen {
    CaptureStatus status;
    uint64_t index;
    uint64_t tick;  // of the buffer the fake delivered last
    cv::Size size;
    int pattern_error;
  };
  std::vector<Seen> seen;
  std::atomic<int> reads{0};
  std::atomic<bool> still_returned{false};
  std::thread reader([&] {
    int reads_after_still = 0;
    const Clock::time_point give_up = Clock::now() + std::chrono::seconds(120);
    while (reads_after_still < 5 && Clock::now() < give_up) {
      const bool after_still = still_returned.load();
      CapturedFrame frame;
      const CaptureStatus status = rig.source->Read(&frame, milliseconds(100));
      const uint64_t tick = rig.fake->deliveries().empty() ? 0 : rig.fake->deliveries().back().tick;
      const int error = status == CaptureStatus::kFrame && frame.image.size() == cv::Size(64, 48)
                            ? YuyvPatternError(frame.image, tick)
                            : -1;
      seen.push_back(Seen{status, frame.frame_index, tick, frame.image.size(), error});
      ++reads;
      if (after_still) ++reads_after_still;
      std::this_thread::sleep_for(milliseconds(1));
    }
  });
  ASSERT_TRUE(WaitUntil([&] { return reads.load() >= 3; }));
  const StillOutcome outcome = CallTakeStill(*rig.source);
  still_returned = true;
  reader.join();

  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  ASSERT_TRUE(outcome.still.has_value());
  const cv::Mat& photo = outcome.still->photo;
  ASSERT_EQ(photo.type(), CV_8UC3);
  ASSERT_EQ(photo.size(), cv::Size(320, 240));
  EXPECT_TRUE(outcome.still->background.empty());
  // Three settle frames, then the photo: Motion-JPEG in two buffers.
  const std::vector<FakeV4l2Delivery> stills = DeliveriesOfSize(*rig.fake, cv::Size(320, 240));
  ASSERT_EQ(stills.size(), 4u);
  for (const FakeV4l2Delivery& delivery : stills) {
    EXPECT_EQ(delivery.pixel_format, V4L2_PIX_FMT_MJPEG);
    EXPECT_LT(delivery.buffer, 2u);
  }
  EXPECT_GT(MjpegPatternPsnr(photo, stills.back().tick), 30.0);
  EXPECT_LT(MjpegPatternPsnr(photo, stills[2].tick), 25.0);

  // Read() only ever returned video frames; across the still the index jumped by the frame
  // periods that passed: the still's stream start (2), its 4 frames, the video's start (2).
  ASSERT_GE(seen.size(), 8u);
  int jumps = 0;
  uint64_t jump = 0;
  for (size_t i = 0; i < seen.size(); ++i) {
    SCOPED_TRACE(i);
    ASSERT_EQ(seen[i].status, CaptureStatus::kFrame);
    ASSERT_EQ(seen[i].size, cv::Size(64, 48));
    EXPECT_EQ(seen[i].index + 2, seen[i].tick);  // frame 0 came 2 periods after Open()
    EXPECT_LE(seen[i].pattern_error, 2);
    if (i == 0) continue;
    ASSERT_GT(seen[i].index, seen[i - 1].index);
    if (seen[i].index - seen[i - 1].index > 1) {
      ++jumps;
      jump = seen[i].index - seen[i - 1].index;
    }
  }
  EXPECT_EQ(jumps, 1);
  EXPECT_EQ(jump, 9u);
  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.frames, seen.size());
  EXPECT_EQ(counters.dropped, 8u);
  EXPECT_EQ(counters.errors, 0u);
  EXPECT_EQ(counters.reopens, 0u);

  // The video format is back exactly: size, pixel format, rate and buffers.
  EXPECT_EQ(rig.source->Describe(), "v4l2:/dev/video0 64x48 YUYV 30 fps");
  EXPECT_EQ(rig.fake->frame_size(), cv::Size(64, 48));
  EXPECT_EQ(rig.fake->pixel_format(), V4L2_PIX_FMT_YUYV);
  EXPECT_DOUBLE_EQ(rig.fake->fps(), 30.0);
  EXPECT_EQ(rig.fake->allocated_buffers(), 4u);
  EXPECT_EQ(rig.fake->streamon_calls(), 3);
  EXPECT_FALSE(rig.source->StillRequested());
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, PrefersMjpegWhenBothFormatsOfferTheLargestSize) {
  FakeV4l2Config config;
  for (const uint32_t format : {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG})
    config.frame_sizes[format] = {FakeFrameSizes::Discrete(64, 48),
                                  FakeFrameSizes::Discrete(320, 240)};
  config.script = Frames(8);
  Rig rig = MakeRig(config, StillOptions());
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);

  const ServedStill served = TakeStillServedByRead(*rig.source);
  ASSERT_TRUE(served.outcome.error.empty()) << served.outcome.error;
  ASSERT_TRUE(served.outcome.still.has_value());
  ASSERT_EQ(served.outcome.still->photo.size(), cv::Size(320, 240));
  const std::vector<FakeV4l2Delivery> stills = DeliveriesOfSize(*rig.fake, cv::Size(320, 240));
  ASSERT_EQ(stills.size(), 4u);
  EXPECT_EQ(stills.back().pixel_format, V4L2_PIX_FMT_MJPEG);
  EXPECT_GT(MjpegPatternPsnr(served.outcome.still->photo, stills.back().tick), 30.0);

  ASSERT_EQ(served.status, CaptureStatus::kFrame);
  EXPECT_EQ(served.frame.image.size(), cv::Size(64, 48));
  EXPECT_EQ(served.frame.frame_index, 5u);  // frame 0, four still frames, then frame 5
  EXPECT_LE(YuyvPatternError(served.frame.image, 5), 2);
  EXPECT_EQ(rig.source->Counters().dropped, 4u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, SearchesStepwiseAndContinuousRanges) {
  struct Case {
    std::string name;
    uint32_t format;
    FakeFrameSizes range;
    cv::Size expected;
  };
  const std::vector<Case> cases = {
      // 936x700 is 1.337:1, within 1 % of 4:3, and larger than 928x696 (exactly 4:3).
      {"stepwise YUYV", V4L2_PIX_FMT_YUYV, FakeFrameSizes::Stepwise({32, 24}, {1000, 700}, {8, 4}),
       cv::Size(936, 700)},
      {"continuous MJPEG", V4L2_PIX_FMT_MJPEG, FakeFrameSizes::Continuous({16, 16}, {400, 300}),
       cv::Size(400, 300)},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    FakeV4l2Config config;
    config.frame_sizes[c.format] = {c.range};
    // The other format offers a smaller 4:3 size.
    const uint32_t other = c.format == V4L2_PIX_FMT_YUYV ? V4L2_PIX_FMT_MJPEG : V4L2_PIX_FMT_YUYV;
    config.frame_sizes[other] = {FakeFrameSizes::Discrete(64, 48),
                                 FakeFrameSizes::Discrete(320, 240)};
    config.script = Frames(6);
    Rig rig = MakeRig(config, StillOptions());
    rig.source->Open();
    ASSERT_EQ(rig.source->Format().width, 64);
    const ServedStill served = TakeStillServedByRead(*rig.source);
    ASSERT_TRUE(served.outcome.error.empty()) << served.outcome.error;
    ASSERT_TRUE(served.outcome.still.has_value());
    const cv::Mat& photo = served.outcome.still->photo;
    ASSERT_EQ(photo.size(), c.expected);
    const std::vector<FakeV4l2Delivery> stills = DeliveriesOfSize(*rig.fake, c.expected);
    ASSERT_EQ(stills.size(), 4u);
    EXPECT_EQ(stills.back().pixel_format, c.format);
    if (c.format == V4L2_PIX_FMT_YUYV) {
      EXPECT_LE(YuyvPatternError(photo, stills.back().tick), 2);
    } else {
      EXPECT_GT(MjpegPatternPsnr(photo, stills.back().tick), 30.0);
    }
    ASSERT_EQ(served.status, CaptureStatus::kFrame);
    EXPECT_EQ(served.frame.image.size(), cv::Size(64, 48));
    ExpectCleanProtocol(*rig.fake);
  }
}

TEST(V4l2SourceStill, SkipsAFewBadFramesAtTheStillSize) {
  FakeV4l2Config config = StillCamera();
  config.script = {FakeV4l2Step::Frame(),
                   // The still: one settle frame, two bad ones, the photo.
                   FakeV4l2Step::Frame(), FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Bad(Kind::kCorruptJpeg), FakeV4l2Step::Frame(),
                   // The video again.
                   FakeV4l2Step::Frame()};
  V4l2SourceOptions options = StillOptions();
  options.still_settle_frames = 1;
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  const ServedStill served = TakeStillServedByRead(*rig.source);
  ASSERT_TRUE(served.outcome.error.empty()) << served.outcome.error;
  ASSERT_TRUE(served.outcome.still.has_value());
  EXPECT_GT(MjpegPatternPsnr(served.outcome.still->photo, 4), 30.0);
  ASSERT_EQ(served.status, CaptureStatus::kFrame);
  EXPECT_EQ(served.frame.frame_index, 5u);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, TooManyBadFramesFailTheStillAndTheVideoGoesOn) {
  FakeV4l2Config config = StillCamera();
  config.script = {FakeV4l2Step::Frame(),
                   FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Bad(Kind::kErrorFrame),
                   FakeV4l2Step::Bad(Kind::kTruncatedJpeg),
                   FakeV4l2Step::Frame()};
  V4l2SourceOptions options = StillOptions();
  options.still_settle_frames = 0;
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  const ServedStill served = TakeStillServedByRead(*rig.source);
  EXPECT_FALSE(served.outcome.still.has_value());
  EXPECT_TRUE(HasText(served.outcome.error, "/dev/video0"));
  EXPECT_TRUE(HasText(served.outcome.error, "bad frames"));
  ASSERT_EQ(served.status, CaptureStatus::kFrame);
  EXPECT_EQ(served.frame.frame_index, 5u);
  EXPECT_LE(YuyvPatternError(served.frame.image, 5), 2);
  EXPECT_EQ(rig.fake->frame_size(), cv::Size(64, 48));
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, IgnoresLargerSizesOfAnotherAspectRatio) {
  FakeV4l2Config config;
  config.frame_sizes[V4L2_PIX_FMT_YUYV] = {FakeFrameSizes::Discrete(64, 48)};
  config.frame_sizes[V4L2_PIX_FMT_MJPEG] = {FakeFrameSizes::Discrete(64, 48),
                                            FakeFrameSizes::Discrete(128, 72),
                                            FakeFrameSizes::Discrete(1280, 720)};
  config.script = Frames(2);
  Rig rig = MakeRig(config, StillOptions());
  rig.source->Open();
  const StillOutcome outcome = CallTakeStill(*rig.source);
  EXPECT_TRUE(outcome.error.empty()) << outcome.error;
  EXPECT_FALSE(outcome.still.has_value());
  EXPECT_FALSE(rig.source->StillRequested());
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(rig.fake->streamon_calls(), 1);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, NoStillWithoutALargerSizeOrSizeEnumeration) {
  FakeV4l2Config smaller_only;
  smaller_only.frame_sizes[V4L2_PIX_FMT_YUYV] = {FakeFrameSizes::Discrete(32, 24),
                                                 FakeFrameSizes::Discrete(64, 48)};
  FakeV4l2Config no_enumeration;  // ENUM_FRAMESIZES is not supported
  for (const FakeV4l2Config& config : {smaller_only, no_enumeration}) {
    Rig rig = MakeRig(config, StillOptions());
    rig.source->Open();
    const StillOutcome outcome = CallTakeStill(*rig.source);
    EXPECT_TRUE(outcome.error.empty()) << outcome.error;
    EXPECT_FALSE(outcome.still.has_value());
    ExpectCleanProtocol(*rig.fake);
  }
}

TEST(V4l2SourceStill, VideoStillsGiveNoStill) {
  V4l2SourceOptions options = StillOptions();
  options.full_resolution_stills = false;
  Rig rig = MakeRig(StillCamera(), options);
  rig.source->Open();
  const StillOutcome outcome = CallTakeStill(*rig.source);
  EXPECT_TRUE(outcome.error.empty()) << outcome.error;
  EXPECT_FALSE(outcome.still.has_value());
  EXPECT_EQ(rig.fake->streamon_calls(), 1);

  // --video-stills reaches the V4L2 source (full-resolution stills need it open).
  SourceOptions source_options;
  source_options.video_stills = true;
  const SourceDescription description{"v4l2", "/nonexistent/silnet-video0"};
  std::unique_ptr<CaptureSource> video = MakeCaptureSource(description, source_options);
  EXPECT_FALSE(video->TakeStill(CapturedFrame{}).has_value());
  source_options.video_stills = false;
  std::unique_ptr<CaptureSource> full = MakeCaptureSource(description, source_options);
  EXPECT_THROW(full->TakeStill(CapturedFrame{}), CaptureError);
}

TEST(V4l2SourceStill, RefusedStillFormatGivesCaptureErrorAndTheVideoGoesOn) {
  FakeV4l2Config config = StillCamera();
  config.refused_sizes = {cv::Size(320, 240)};
  config.script = Frames(4);
  Rig rig = MakeRig(config, StillOptions());
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);

  const ServedStill served = TakeStillServedByRead(*rig.source);
  EXPECT_FALSE(served.outcome.still.has_value());
  EXPECT_TRUE(HasText(served.outcome.error, "/dev/video0"));
  EXPECT_TRUE(HasText(served.outcome.error, "VIDIOC_S_FMT"));
  ASSERT_EQ(served.status, CaptureStatus::kFrame) << rig.source->LastError();
  EXPECT_EQ(served.frame.image.size(), cv::Size(64, 48));
  EXPECT_EQ(served.frame.frame_index, 2u);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 3u);
  EXPECT_LE(YuyvPatternError(frame.image, 3), 2);
  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.errors, 0u);
  EXPECT_EQ(counters.reopens, 0u);
  EXPECT_EQ(counters.dropped, 0u);
  EXPECT_EQ(rig.fake->open_attempts(), 1);
  EXPECT_EQ(rig.fake->allocated_buffers(), 4u);
  ExpectCleanProtocol(*rig.fake);
}

// The device disappears while the still streams: through POLLERR (0) or DQBUF failing.
class V4l2SourceStillLossTest : public ::testing::TestWithParam<int> {};

TEST_P(V4l2SourceStillLossTest, DeviceLostDuringTheStillIsReopened) {
  FakeV4l2Config config = StillCamera();
  config.script = {FakeV4l2Step::Frame(), FakeV4l2Step::Frame(),
                   // The still: a settle frame, then the camera is unplugged for 5 periods.
                   FakeV4l2Step::Frame(), FakeV4l2Step::Disappear(GetParam(), 1, 5),
                   FakeV4l2Step::Frame(), FakeV4l2Step::Frame()};
  Rig rig = MakeRig(config, StillOptions());
  rig.source->Open();
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);

  const ServedStill served = TakeStillServedByRead(*rig.source);
  EXPECT_FALSE(served.outcome.still.has_value());
  EXPECT_TRUE(HasText(served.outcome.error, "/dev/video0"));
  ASSERT_EQ(served.status, CaptureStatus::kError);
  EXPECT_TRUE(HasText(rig.source->LastError(), "device lost"));
  EXPECT_EQ(rig.fake->open_descriptors(), 0u);
  EXPECT_EQ(rig.fake->mappings(), 0u);

  // A still while the device is away fails at once.
  const ServedStill away = TakeStillServedByRead(*rig.source);
  EXPECT_TRUE(HasText(away.outcome.error, "away"));
  EXPECT_EQ(away.status, CaptureStatus::kTimeout);  // the one failed re-open

  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame) << rig.source->LastError();
  EXPECT_EQ(frame.frame_index, 8u);  // 1 + the 7 periods since frame 1 (one still frame, 5 away)
  EXPECT_EQ(frame.image.size(), cv::Size(64, 48));
  EXPECT_LE(YuyvPatternError(frame.image, 8), 2);
  const CaptureCounters counters = rig.source->Counters();
  EXPECT_EQ(counters.reopens, 1u);
  EXPECT_EQ(counters.errors, 1u);
  EXPECT_EQ(counters.dropped, 6u);
  EXPECT_EQ(rig.fake->open_descriptors(), 1u);
  EXPECT_EQ(rig.fake->frame_size(), cv::Size(64, 48));
  ExpectCleanProtocol(*rig.fake);
}

INSTANTIATE_TEST_SUITE_P(LossKinds, V4l2SourceStillLossTest, ::testing::Values(0, ENODEV),
                         [](const ::testing::TestParamInfo<int>& loss) {
                           return loss.param == 0 ? std::string("PollError")
                                                  : std::string("Enodev");
                         });

TEST(V4l2SourceStill, TimesOutWhenNobodyReads) {
  FakeV4l2Config config = StillCamera();
  config.script = Frames(2);
  V4l2SourceOptions options = StillOptions();
  options.still_timeout = milliseconds(200);
  Rig rig = MakeRig(config, options);
  rig.source->Open();
  const Clock::time_point start = Clock::now();
  const StillOutcome outcome = CallTakeStill(*rig.source);
  EXPECT_GE(Clock::now() - start, milliseconds(200));
  EXPECT_FALSE(outcome.still.has_value());
  EXPECT_TRUE(HasText(outcome.error, "/dev/video0"));
  EXPECT_TRUE(HasText(outcome.error, "no still within 200 ms"));
  EXPECT_FALSE(rig.source->StillRequested());

  // The abandoned request is not performed later.
  CapturedFrame frame;
  ASSERT_EQ(ReadOnce(*rig.source, &frame), CaptureStatus::kFrame);
  EXPECT_EQ(frame.frame_index, 0u);
  EXPECT_EQ(rig.fake->streamon_calls(), 1);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, CloseWakesAWaitingStill) {
  Rig rig = MakeRig(StillCamera(), StillOptions());
  rig.source->Open();
  std::future<StillOutcome> taking =
      std::async(std::launch::async, [&rig] { return CallTakeStill(*rig.source); });
  ASSERT_TRUE(WaitUntil([&] { return rig.source->StillRequested(); }));
  rig.source->Close();
  ASSERT_EQ(taking.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  const StillOutcome outcome = taking.get();
  EXPECT_FALSE(outcome.still.has_value());
  EXPECT_TRUE(HasText(outcome.error, "/dev/video0"));
  EXPECT_TRUE(HasText(outcome.error, "closed"));
  EXPECT_FALSE(rig.source->StillRequested());

  const StillOutcome closed = CallTakeStill(*rig.source);
  EXPECT_TRUE(HasText(closed.error, "not open"));
  EXPECT_EQ(rig.fake->streamon_calls(), 1);
  ExpectCleanProtocol(*rig.fake);
}

TEST(V4l2SourceStill, RejectsBadStillOptions) {
  V4l2SourceOptions options = StillOptions();
  options.still_settle_frames = -1;
  EXPECT_TRUE(HasText(ConstructionError(options), "settle frames"));
  options = StillOptions();
  options.still_timeout = milliseconds(0);
  EXPECT_TRUE(HasText(ConstructionError(options), "still timeout"));
  options = StillOptions();
  options.still_settle_frames = 0;
  EXPECT_EQ(ConstructionError(options), "");
}

TEST(FakeV4l2Device, EnumeratesFrameSizesAndRefusesFormatChangesWhileBusy) {
  FakeV4l2Config config;
  config.frame_sizes[V4L2_PIX_FMT_YUYV] = {FakeFrameSizes::Discrete(64, 48),
                                           FakeFrameSizes::Discrete(320, 240)};
  config.frame_sizes[V4L2_PIX_FMT_MJPEG] = {
      FakeFrameSizes::Stepwise({32, 24}, {640, 480}, {16, 12})};
  FakeV4l2Device fake(config);
  const int fd = fake.Open("/dev/video0", 0);
  ASSERT_GE(fd, 0);

  v4l2_frmsizeenum entry{};
  entry.pixel_format = V4L2_PIX_FMT_YUYV;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), 0);
  EXPECT_EQ(entry.type, static_cast<uint32_t>(V4L2_FRMSIZE_TYPE_DISCRETE));
  EXPECT_EQ(entry.discrete.width, 64u);
  entry.index = 1;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), 0);
  EXPECT_EQ(entry.discrete.height, 240u);
  entry.index = 2;
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), -1);
  EXPECT_EQ(errno, EINVAL);
  entry = v4l2_frmsizeenum{};
  entry.pixel_format = V4L2_PIX_FMT_MJPEG;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), 0);
  EXPECT_EQ(entry.type, static_cast<uint32_t>(V4L2_FRMSIZE_TYPE_STEPWISE));
  EXPECT_EQ(entry.stepwise.max_width, 640u);
  EXPECT_EQ(entry.stepwise.step_height, 12u);
  entry.index = 1;
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), -1);
  entry = v4l2_frmsizeenum{};
  entry.pixel_format = V4L2_PIX_FMT_NV12;
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &entry), -1);
  EXPECT_EQ(errno, EINVAL);

  // S_FMT grants the nearest listed size, or the range's nearest step.
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  format.fmt.pix.width = 300;
  format.fmt.pix.height = 200;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_S_FMT, &format), 0);
  EXPECT_EQ(fake.frame_size(), cv::Size(320, 240));
  format.fmt.pix.pixelformat = V4L2_PIX_FMT_MJPEG;
  format.fmt.pix.width = 100;
  format.fmt.pix.height = 100;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_S_FMT, &format), 0);
  EXPECT_EQ(fake.frame_size(), cv::Size(96, 96));
  EXPECT_TRUE(fake.violations().empty());

  // The format cannot change while buffers are allocated, streaming or not.
  v4l2_requestbuffers request{};
  request.count = 2;
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_REQBUFS, &request), 0);
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_S_FMT, &format), -1);
  EXPECT_EQ(errno, EBUSY);
  ASSERT_EQ(fake.violations().size(), 1u);
  EXPECT_TRUE(HasText(fake.violations()[0], "buffers are allocated"));
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_STREAMON, &type), 0);
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_S_FMT, &format), -1);
  ASSERT_EQ(fake.violations().size(), 2u);
  EXPECT_TRUE(HasText(fake.violations()[1], "while streaming"));
  EXPECT_EQ(fake.frame_size(), cv::Size(96, 96));
  EXPECT_EQ(fake.Close(fd), 0);

  FakeV4l2Device no_sizes(FakeV4l2Config{});
  const int other = no_sizes.Open("/dev/video0", 0);
  entry = v4l2_frmsizeenum{};
  entry.pixel_format = V4L2_PIX_FMT_YUYV;
  EXPECT_EQ(no_sizes.Ioctl(other, VIDIOC_ENUM_FRAMESIZES, &entry), -1);
  EXPECT_EQ(errno, ENOTTY);
  EXPECT_EQ(no_sizes.Close(other), 0);
}

TEST(FakeV4l2Device, RecordsProtocolViolations) {
  FakeV4l2Config config;
  config.script = Frames(1);
  FakeV4l2Device fake(config);
  const int fd = fake.Open("/dev/video0", 0);
  ASSERT_GE(fd, 0);

  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_DQBUF, &buffer), -1);
  EXPECT_EQ(errno, EINVAL);
  ASSERT_EQ(fake.violations().size(), 1u);
  EXPECT_TRUE(HasText(fake.violations()[0], "before VIDIOC_STREAMON"));

  v4l2_requestbuffers request{};
  request.count = 2;
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_REQBUFS, &request), 0);
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_QBUF, &buffer), 0);
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_QBUF, &buffer), -1);
  ASSERT_EQ(fake.violations().size(), 2u);
  EXPECT_TRUE(HasText(fake.violations()[1], "not dequeued"));

  EXPECT_EQ(fake.Mmap(4096, fd, 0x7777), MAP_FAILED);
  ASSERT_EQ(fake.violations().size(), 3u);
  EXPECT_TRUE(HasText(fake.violations()[2], "unknown offset"));

  buffer.index = 1;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_QUERYBUF, &buffer), 0);
  void* address = fake.Mmap(buffer.length, fd, static_cast<off_t>(buffer.m.offset));
  ASSERT_NE(address, MAP_FAILED);
  request.count = 0;
  EXPECT_EQ(fake.Ioctl(fd, VIDIOC_REQBUFS, &request), -1);
  ASSERT_EQ(fake.violations().size(), 4u);
  EXPECT_TRUE(HasText(fake.violations()[3], "still mapped"));

  // Buffer 1 was never queued: the second frame finds no buffer.
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_STREAMON, &type), 0);
  EXPECT_NE(fake.Poll(fd, 0) & POLLIN, 0);
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_DQBUF, &buffer), 0);
  EXPECT_EQ(buffer.index, 0u);
  EXPECT_EQ(fake.violations().size(), 4u);

  EXPECT_EQ(fake.Ioctl(999, VIDIOC_QUERYCAP, &buffer), -1);
  EXPECT_EQ(fake.violations().size(), 5u);
  EXPECT_EQ(fake.Munmap(address, buffer.length), 0);
  EXPECT_EQ(fake.Close(fd), 0);
  EXPECT_EQ(fake.Close(fd), -1);
  EXPECT_EQ(fake.violations().size(), 6u);
}

TEST(FakeV4l2Device, CountsFramesThatFindNoQueuedBuffer) {
  FakeV4l2Config config;
  config.script = Frames(2);
  FakeV4l2Device fake(config);
  const int fd = fake.Open("/dev/video0", 0);
  v4l2_requestbuffers request{};
  request.count = 1;
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_REQBUFS, &request), 0);
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(fake.Ioctl(fd, VIDIOC_STREAMON, &type), 0);
  EXPECT_NE(fake.Poll(fd, 0) & POLLERR, 0);
  EXPECT_EQ(fake.starved_frames(), 1u);
  EXPECT_EQ(fake.Close(fd), 0);
}

}  // namespace
}  // namespace silnet::node
