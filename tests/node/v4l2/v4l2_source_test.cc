#include "node/capture/v4l2/v4l2_source.h"

#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <poll.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tests/node/v4l2/fake_v4l2_device.h"

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

TEST(V4l2Source, RejectsBadOptionsNamingTheDevice) {
  const auto error_of = [](V4l2SourceOptions options) -> std::string {
    try {
      V4l2Source source(std::move(options),
                        FakeV4l2Device::Handle(std::make_shared<FakeV4l2Device>(FakeV4l2Config{})));
    } catch (const CaptureError& e) {
      return e.what();
    }
    return "";
  };
  V4l2SourceOptions options = SmallOptions();
  options.width = 0;
  EXPECT_TRUE(HasText(error_of(options), "/dev/video0"));
  options = SmallOptions();
  options.fps = -1.0;
  EXPECT_TRUE(HasText(error_of(options), "frame rate"));
  options = SmallOptions();
  options.buffer_count = 0;
  EXPECT_TRUE(HasText(error_of(options), "buffer count"));
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
