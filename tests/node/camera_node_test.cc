// A CameraNode run in-process over loopback DDS, driven by commands from a test participant:
// set-parameter, capture-still, stop/start, record start/stop; its status and camera info.

#include "node/camera_node.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "node/capture/files/image_folder_source.h"
#include "shared/dds/sample_conversions.h"
#include "shared/io/session_log_reader.h"
#include "shared/util/crc32.h"
#include "tests/support/eventually.h"
#include "tests/support/temp_dir.h"

namespace silnet::node {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// Checks `condition` every 20 ms for up to 10 s (testing::Eventually).
bool Eventually(const std::function<bool()>& condition) {
  return testing::Eventually(condition, milliseconds(10000), milliseconds(20));
}

class CameraNodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int k = 0; k < 200; ++k) {
      cv::Mat mask(96, 128, CV_8U, cv::Scalar(0));
      cv::circle(mask, {30 + k % 60, 48}, 15, 255, -1);
      cv::imwrite(dir_.path().string() + "/f" + std::to_string(1000 + k) + ".png", mask);
    }
    ImageFolderSourceOptions source;
    source.folder = dir_.path();
    source.masks = true;
    source.fps = 25.0;
    source.real_time = true;
    CameraNodeOptions options;
    options.processing.camera_id = "camT";
    options.processing.session = 9;
    options.processing.segmentation.method = SegmentationMethod::kMaskInput;
    options.status_period = milliseconds(200);
    options.linger = milliseconds(500);
    options.domain = dds::DomainConfig::FromEnvironment();
    node_ = std::make_unique<CameraNode>(options, MakeSource(source));
    runner_ = std::thread([this] { node_->Run(stop_); });
  }
  void TearDown() override {
    stop_ = true;
    runner_.join();
  }
  virtual std::unique_ptr<CaptureSource> MakeSource(const ImageFolderSourceOptions& options) {
    return std::make_unique<ImageFolderSource>(options);
  }

  // Takes still `id` (of the empty scene when `background`) and returns its two parts.
  std::map<silnet_wire_StillPart, cv::Mat> TakeStill(uint64_t id, bool background) {
    silnet_wire_Command capture{};
    capture.still_id = id;
    Send(silnet_wire_COMMAND_CAPTURE_STILL, background ? "still" : "",
         background ? "background" : "", &capture);
    std::map<silnet_wire_StillPart, std::vector<uint8_t>> bytes;
    std::map<silnet_wire_StillPart, uint32_t> chunks, expected_chunks;
    const bool arrived = Eventually([&] {
      stills_.Take([&](const silnet_wire_Still& s, const dds_sample_info_t&) {
        if (s.still_id != id) return;
        bytes[s.part].insert(bytes[s.part].end(), s.data._buffer, s.data._buffer + s.data._length);
        expected_chunks[s.part] = s.chunk_count;
        ++chunks[s.part];
      });
      return chunks.size() == 2 && chunks == expected_chunks;
    });
    std::map<silnet_wire_StillPart, cv::Mat> parts;
    if (!arrived) return parts;
    parts[silnet_wire_STILL_PHOTO] =
        cv::imdecode(bytes[silnet_wire_STILL_PHOTO], cv::IMREAD_UNCHANGED);
    parts[silnet_wire_STILL_SILHOUETTE] =
        cv::imdecode(bytes[silnet_wire_STILL_SILHOUETTE], cv::IMREAD_GRAYSCALE);
    return parts;
  }

  void Send(silnet_wire_CommandKind kind, const std::string& name = "",
            const std::string& value = "", const silnet_wire_Command* base = nullptr) {
    silnet_wire_Command command = base ? *base : silnet_wire_Command{};
    command.command_id = ++command_id_;
    dds::CopyBoundedString("test", command.issuer, "issuer");
    dds::CopyBoundedString("camT", command.target, "target");
    command.kind = kind;
    dds::CopyBoundedString(name, command.parameter.name, "name");
    dds::CopyBoundedString(value, command.parameter.value, "value");
    ASSERT_TRUE(command_writer_.Write(command));
  }

  testing::TempDir dir_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<CameraNode> node_;
  std::thread runner_;
  dds::Participant participant_;
  dds::Topic<silnet_wire_Command> command_topic_{participant_};
  dds::Writer<silnet_wire_Command> command_writer_{command_topic_};
  dds::Topic<silnet_wire_HullFrame> hull_topic_{participant_};
  dds::Reader<silnet_wire_HullFrame> hulls_{hull_topic_};
  dds::Topic<silnet_wire_CameraInfo> info_topic_{participant_};
  dds::Reader<silnet_wire_CameraInfo> infos_{info_topic_};
  dds::Topic<silnet_wire_NodeStatus> status_topic_{participant_};
  dds::Reader<silnet_wire_NodeStatus> statuses_{status_topic_};
  dds::Topic<silnet_wire_Still> still_topic_{participant_};
  dds::Reader<silnet_wire_Still> stills_{still_topic_};
  uint64_t command_id_ = 0;
};

TEST_F(CameraNodeTest, ObeysCommandsAndReportsItsState) {
  ASSERT_TRUE(command_writer_.WaitForReaders(1, seconds(10)));
  // Camera info is latched and describes the node.
  CameraInfoRecord info;
  ASSERT_TRUE(Eventually([&] {
    infos_.Take([&](const silnet_wire_CameraInfo& s, const dds_sample_info_t&) {
      info = dds::FromWire(s);
    });
    return !info.camera_id.empty();
  }));
  EXPECT_EQ(info.camera_id, "camT");
  EXPECT_EQ(info.width, 128);
  EXPECT_EQ(info.segmentation, "mask");
  EXPECT_EQ(info.parameters.at("min_blob_area"), "120");

  // Set a parameter: the node re-publishes its camera info.
  Send(silnet_wire_COMMAND_SET_PARAMETER, "min_blob_area", "77");
  ASSERT_TRUE(Eventually([&] {
    infos_.Take([&](const silnet_wire_CameraInfo& s, const dds_sample_info_t&) {
      info = dds::FromWire(s);
    });
    return info.parameters.at("min_blob_area") == "77";
  }));

  // A still arrives in checksummed chunks: the photo decodes to one of the camera's frames,
  // the silhouette part is of the same frame and size.
  silnet_wire_Command capture{};
  capture.still_id = 5;
  Send(silnet_wire_COMMAND_CAPTURE_STILL, "", "", &capture);
  std::map<silnet_wire_StillPart, std::vector<uint8_t>> bytes;
  std::map<silnet_wire_StillPart, uint32_t> chunks, expected_chunks;
  std::map<silnet_wire_StillPart, uint64_t> frames;
  ASSERT_TRUE(Eventually([&] {
    stills_.Take([&](const silnet_wire_Still& s, const dds_sample_info_t&) {
      EXPECT_EQ(s.still_id, 5u);
      EXPECT_EQ(Crc32(0, s.data._buffer, s.data._length), s.chunk_crc32);
      bytes[s.part].insert(bytes[s.part].end(), s.data._buffer, s.data._buffer + s.data._length);
      expected_chunks[s.part] = s.chunk_count;
      frames[s.part] = s.frame_index;
      ++chunks[s.part];
    });
    return chunks.size() == 2 && chunks == expected_chunks;
  }));
  const cv::Mat still = cv::imdecode(bytes[silnet_wire_STILL_PHOTO], cv::IMREAD_UNCHANGED);
  ASSERT_EQ(still.size(), cv::Size(128, 96));
  EXPECT_GT(cv::countNonZero(still), 500);
  const cv::Mat silhouette =
      cv::imdecode(bytes[silnet_wire_STILL_SILHOUETTE], cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(silhouette.size(), cv::Size(128, 96));
  EXPECT_EQ(frames[silnet_wire_STILL_PHOTO], frames[silnet_wire_STILL_SILHOUETTE]);

  // Stop: no new frames; start: frames again.
  Send(silnet_wire_COMMAND_STOP);
  std::this_thread::sleep_for(milliseconds(300));
  hulls_.Take([](const silnet_wire_HullFrame&, const dds_sample_info_t&) {}, 100000);
  std::this_thread::sleep_for(milliseconds(500));
  size_t while_stopped =
      hulls_.Take([](const silnet_wire_HullFrame&, const dds_sample_info_t&) {}, 100000);
  EXPECT_LE(while_stopped, 1u);
  Send(silnet_wire_COMMAND_START);
  size_t after_start = 0;
  ASSERT_TRUE(Eventually([&] {
    after_start +=
        hulls_.Take([](const silnet_wire_HullFrame&, const dds_sample_info_t&) {}, 100000);
    return after_start > 3;
  }));

  // Recording on command.
  Send(silnet_wire_COMMAND_RECORD_START, "", (dir_ / "rec").string());
  std::this_thread::sleep_for(milliseconds(600));
  Send(silnet_wire_COMMAND_RECORD_STOP);
  ASSERT_TRUE(
      Eventually([&] { return std::filesystem::exists(SessionLogPath(dir_ / "rec", "camT")); }));
  std::this_thread::sleep_for(milliseconds(200));
  const auto recorded = ReadSessionLog(SessionLogPath(dir_ / "rec", "camT"));
  ASSERT_EQ(recorded.size(), 1u);
  EXPECT_GT(recorded[0].hulls.size(), 5u);
  EXPECT_EQ(recorded[0].info.parameters.at("min_blob_area"), "77");

  // Status: running at about the source's rate, with commands counted.
  silnet_wire_NodeStatus status{};
  ASSERT_TRUE(Eventually([&] {
    statuses_.Take([&](const silnet_wire_NodeStatus& s, const dds_sample_info_t&) { status = s; });
    return status.fps > 10.0;
  }));
  EXPECT_EQ(dds::ReadBoundedString(status.camera_id), "camT");
  EXPECT_EQ(status.session, 9u);
  EXPECT_NE(dds::ReadBoundedString(status.state).find("running"), std::string::npos);
  EXPECT_GE(node_->Counters().commands, 6u);
}

// A source with a still stream of its own at twice the frames' size and no background for it
// (as a V4L2 or libcamera camera): the still it takes is whatever the test put in `scene`.
class StillStreamSource : public CaptureSource {
 public:
  StillStreamSource(const ImageFolderSourceOptions& options, std::shared_ptr<cv::Mat> scene)
      : frames_(options), scene_(std::move(scene)) {}
  void Open() override { frames_.Open(); }
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override {
    return frames_.Read(frame, timeout);
  }
  void Close() override { frames_.Close(); }
  CaptureFormat Format() const override { return frames_.Format(); }
  std::string Kind() const override { return "test"; }
  std::string Describe() const override { return "still stream test source"; }
  std::string LastError() const override { return frames_.LastError(); }
  CaptureCounters Counters() const override { return frames_.Counters(); }
  std::optional<StillPhoto> TakeStill(const CapturedFrame&) override {
    StillPhoto still;
    still.photo = scene_->clone();
    return still;
  }

 private:
  ImageFolderSource frames_;
  std::shared_ptr<cv::Mat> scene_;
};

class CameraNodeStillStreamTest : public CameraNodeTest {
 protected:
  std::unique_ptr<CaptureSource> MakeSource(const ImageFolderSourceOptions& options) override {
    return std::make_unique<StillStreamSource>(options, scene_);
  }
  std::shared_ptr<cv::Mat> scene_ = std::make_shared<cv::Mat>();
};

// Without a background of its own, a full-resolution still's silhouette is the frame's brought
// to its size; once the node has a still of the empty scene, it is the still's own, against it.
TEST_F(CameraNodeStillStreamTest, SegmentsStillsAgainstItsStillOfTheEmptyScene) {
  cv::Mat empty(192, 256, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(empty, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(190));
  const cv::Rect subject(150, 40, 60, 110);  // where the frames' circle never is
  cv::Mat with_subject = empty.clone();
  with_subject(subject).setTo(cv::Scalar(30, 40, 220));
  ASSERT_TRUE(command_writer_.WaitForReaders(1, seconds(10)));

  *scene_ = with_subject.clone();
  auto before = TakeStill(11, false);
  ASSERT_EQ(before.size(), 2u);
  ASSERT_EQ(before[silnet_wire_STILL_SILHOUETTE].size(), cv::Size(256, 192));
  EXPECT_LT(cv::countNonZero(before[silnet_wire_STILL_SILHOUETTE](subject)), subject.area() / 10)
      << "the frame's circle, scaled, is elsewhere";

  *scene_ = empty.clone();
  auto background = TakeStill(12, true);
  ASSERT_EQ(background.size(), 2u);
  EXPECT_EQ(cv::norm(background[silnet_wire_STILL_PHOTO], empty, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(background[silnet_wire_STILL_SILHOUETTE]), 0);

  *scene_ = with_subject.clone();
  auto after = TakeStill(13, false);
  ASSERT_EQ(after.size(), 2u);
  cv::Mat expected = cv::Mat::zeros(192, 256, CV_8UC1);
  expected(subject).setTo(255);
  // Read as readers read masks (>= 128): the node also marks weak evidence beside the outline
  // (node/segmentation/weak_silhouette.h) for the aggregator to confirm.
  const cv::Mat silhouette = after[silnet_wire_STILL_SILHOUETTE] >= 128;
  EXPECT_LE(cv::norm(silhouette, expected, cv::NORM_L1) / 255, 10);
}

}  // namespace
}  // namespace silnet::node
