// The ingest against a hostile publisher: duplicated, out-of-order and malformed samples are
// rejected or stored once, and counted; gaps are asked for with re-send commands.

#include "aggregator/ingest/ingest_service.h"

#include <gtest/gtest.h>

#include <functional>
#include <opencv2/core/persistence.hpp>
#include <vector>

#include "shared/dds/sample_conversions.h"
#include "shared/silhouette/hull_codec.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

using std::chrono::milliseconds;

FrameRecord Good(uint64_t index) {
  FrameRecord r;
  r.camera_id = "cam05";
  r.session = 3;
  r.frame_index = index;
  r.width = 640;
  r.height = 480;
  HullPayload payload;
  payload.hull = SilhouetteHull({{10.5, 10}, {50, 12.5}, {30, 40}}, {false, false, false});
  r.payload = EncodeHull(payload);
  return r;
}

// An ingest storing into `dir`, on the test's DDS domain.
IngestOptions StoringIn(const testing::TempDir& dir) {
  IngestOptions options;
  options.store_dir = dir / "store";
  options.domain = dds::DomainConfig::FromEnvironment();
  return options;
}

TEST(IngestService, CountsDuplicatesOutOfOrderAndMalformedSamplesAndAsksForGaps) {
  testing::TempDir dir;
  IngestOptions options = StoringIn(dir);
  options.resend_grace = milliseconds(50);
  IngestService ingest(options);
  ingest.Open();

  dds::Participant participant(options.domain);
  dds::Topic<silnet_wire_HullFrame> topic(participant);
  dds::Writer<silnet_wire_HullFrame> writer(topic);
  dds::Topic<silnet_wire_Command> command_topic(participant);
  dds::Reader<silnet_wire_Command> commands(command_topic);
  ASSERT_TRUE(writer.WaitForReaders(1, std::chrono::seconds(10)));
  auto send = [&](const FrameRecord& r) {
    silnet_wire_HullFrame sample;
    dds::ToWire(r, &sample);
    ASSERT_TRUE(writer.Write(sample));
  };
  for (uint64_t i : {0u, 1u, 2u, 5u, 4u, 2u, 6u})
    send(Good(i));  // 3 missing, 4 late, 2 twice
  FrameRecord corrupt = Good(7);
  corrupt.payload[3] ^= 0xFF;
  send(corrupt);
  FrameRecord truncated = Good(8);
  truncated.payload.resize(5);
  send(truncated);
  FrameRecord nameless = Good(9);
  nameless.camera_id = "";
  send(nameless);
  FrameRecord no_size = Good(10);
  no_size.width = 0;
  send(no_size);
  ASSERT_TRUE(writer.WaitForAcknowledgements(std::chrono::seconds(10)));

  std::vector<silnet_wire_Command> resends;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (resends.empty() && std::chrono::steady_clock::now() < deadline) {
    ingest.Poll(milliseconds(50));
    commands.Take(
        [&](const silnet_wire_Command& c, const dds_sample_info_t&) { resends.push_back(c); });
  }
  const auto status = ingest.Status();
  ASSERT_EQ(status.size(), 1u);
  const CameraIngestStatus& c = status[0];
  EXPECT_EQ(c.camera_id, "cam05");
  EXPECT_EQ(c.session, 3u);
  EXPECT_EQ(c.frames_held, 6u);
  EXPECT_EQ(c.missing, 1u);
  EXPECT_EQ(c.duplicates, 1u);
  EXPECT_EQ(c.out_of_order, 1u);
  EXPECT_EQ(c.malformed, 3u);
  EXPECT_EQ(ingest.Totals().malformed, 4u);
  ASSERT_FALSE(resends.empty());
  EXPECT_EQ(resends[0].kind, silnet_wire_COMMAND_RESEND);
  EXPECT_EQ(dds::ReadBoundedString(resends[0].target), "cam05");
  EXPECT_EQ(resends[0].session, 3u);
  EXPECT_EQ(resends[0].from_frame, 3u);
  EXPECT_EQ(resends[0].to_frame, 3u);
}

// The DDS side of a node for the contour tests: hull frames and its CameraInfo, each sample
// acknowledged by the ingest before the next step, and the commands it receives from then on.
struct NodeSide {
  explicit NodeSide(const dds::DomainConfig& domain)
      : participant(domain),
        hull_topic(participant),
        hulls(hull_topic),
        info_topic(participant),
        info(info_topic),
        command_topic(participant),
        commands(command_topic) {
    EXPECT_TRUE(hulls.WaitForReaders(1, std::chrono::seconds(10)));
    EXPECT_TRUE(info.WaitForReaders(1, std::chrono::seconds(10)));
  }
  void Send(const FrameRecord& r) {
    silnet_wire_HullFrame sample;
    dds::ToWire(r, &sample);
    ASSERT_TRUE(hulls.Write(sample));
    ASSERT_TRUE(hulls.WaitForAcknowledgements(std::chrono::seconds(10)));
  }
  // Announces a contour with every frame.
  void SendContourRate() {
    CameraInfoRecord record;
    record.camera_id = "cam05";
    record.session = 3;
    record.width = 640;
    record.height = 480;
    record.nominal_fps = 30;
    record.parameters["contour_every"] = "1";
    silnet_wire_CameraInfo sample{};
    std::vector<silnet_wire_Parameter> storage;
    dds::ToWire(record, &sample, &storage);
    ASSERT_TRUE(info.Write(sample));
    ASSERT_TRUE(info.WaitForAcknowledgements(std::chrono::seconds(10)));
  }

  dds::Participant participant;
  dds::Topic<silnet_wire_HullFrame> hull_topic;
  dds::Writer<silnet_wire_HullFrame> hulls;
  dds::Topic<silnet_wire_CameraInfo> info_topic;
  dds::Writer<silnet_wire_CameraInfo> info;
  dds::Topic<silnet_wire_Command> command_topic;
  dds::Reader<silnet_wire_Command> commands;
};

// Polls the ingest until `done` holds (10 s at most); true if it does.
bool PollUntil(IngestService& ingest, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done() && std::chrono::steady_clock::now() < deadline)
    ingest.Poll(milliseconds(20));
  return done();
}

// Polls until the ingest asks for contours again and returns the first frames asked for.
std::vector<uint64_t> FirstFramesAskedFor(IngestService& ingest, NodeSide& node) {
  std::vector<uint64_t> first;
  PollUntil(ingest, [&] {
    node.commands.Take([&](const silnet_wire_Command& c, const dds_sample_info_t&) {
      if (c.kind == silnet_wire_COMMAND_RESEND) first.push_back(c.from_frame);
    });
    return !first.empty();
  });
  return first;
}

// Frames a node dropped or could not use have no contour. When the node's contour rate
// arrives after them, or reaches an aggregator restarted over the store that holds them, only
// the frames that should have a contour are waited for and asked for (a node_stream test
// under load asked for two dropped frames until the ingest gave up).
TEST(IngestService, FramesWithoutContourAreNeverWaitedForWhenTheContourRateArrivesLate) {
  testing::TempDir dir;
  IngestOptions options = StoringIn(dir);
  options.resend_grace = milliseconds(50);
  options.resend_interval = milliseconds(100);
  std::vector<FrameRecord> frames = {Good(0), Good(1), Good(2)};
  frames[0].flags = silnet_wire_FRAME_DROPPED;
  frames[1].flags = silnet_wire_FRAME_BAD_INPUT;
  {
    IngestService ingest(options);
    ingest.Open();
    NodeSide node(options.domain);
    for (const FrameRecord& r : frames)
      node.Send(r);
    ASSERT_TRUE(PollUntil(
        ingest, [&] { return !ingest.Status().empty() && ingest.Status()[0].frames_held == 3; }));
    node.SendContourRate();
    EXPECT_EQ(FirstFramesAskedFor(ingest, node), std::vector<uint64_t>{2});
    EXPECT_EQ(ingest.Totals().contours_overdue, 1u);
  }
  // Restarted over the store that holds the three frames: their flags are read back from it.
  IngestService ingest(options);
  ingest.Open();
  NodeSide node(options.domain);
  node.SendContourRate();
  ASSERT_TRUE(PollUntil(ingest, [&] { return !ingest.Status().empty(); }));
  node.Send(Good(3));
  EXPECT_EQ(FirstFramesAskedFor(ingest, node), std::vector<uint64_t>{2});
  EXPECT_EQ(ingest.Totals().contours_overdue, 2u);  // frames 2 and 3
}

// A node's own losses reach the camera's status, the totals and the summary file.
TEST(IngestService, KeepsWhatTheNodesReportDroppedAndFlagged) {
  testing::TempDir dir;
  const IngestOptions options = StoringIn(dir);
  IngestService ingest(options);
  ingest.Open();

  dds::Participant participant(options.domain);
  dds::Topic<silnet_wire_HullFrame> topic(participant);
  dds::Writer<silnet_wire_HullFrame> writer(topic);
  dds::Topic<silnet_wire_NodeStatus> status_topic(participant);
  dds::Writer<silnet_wire_NodeStatus> status_writer(status_topic);
  ASSERT_TRUE(writer.WaitForReaders(1, std::chrono::seconds(10)));
  ASSERT_TRUE(status_writer.WaitForReaders(1, std::chrono::seconds(10)));
  const FrameRecord record = Good(0);  // the sample points into it
  silnet_wire_HullFrame frame;
  dds::ToWire(record, &frame);
  ASSERT_TRUE(writer.Write(frame));
  ASSERT_TRUE(writer.WaitForAcknowledgements(std::chrono::seconds(10)));
  // The camera's session is known once its frame is in; statuses of other sessions are not
  // counted.
  for (auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
       ingest.Status().empty() && std::chrono::steady_clock::now() < until;)
    ingest.Poll(milliseconds(50));
  silnet_wire_NodeStatus status{};
  dds::CopyBoundedString("cam05", status.camera_id, "camera id");
  dds::CopyBoundedString("running", status.state, "state");
  status.session = 3;
  status.frames_published = 40;
  status.frames_dropped = 7;
  status.frames_flagged = 9;
  ASSERT_TRUE(status_writer.Write(status));
  ASSERT_TRUE(status_writer.WaitForAcknowledgements(std::chrono::seconds(10)));

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline &&
         (ingest.Status().empty() || ingest.Status()[0].node_flagged == 0))
    ingest.Poll(milliseconds(50));
  const auto cameras = ingest.Status();
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].node_dropped, 7u);
  EXPECT_EQ(cameras[0].node_flagged, 9u);
  EXPECT_EQ(ingest.Totals().node_dropped, 7u);
  EXPECT_EQ(ingest.Totals().node_flagged, 9u);
  ingest.WriteSummary(dir / "ingest_summary.yaml");
  cv::FileStorage summary((dir / "ingest_summary.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(summary.isOpened());
  EXPECT_EQ(static_cast<double>(summary["cameras"][0]["node_flagged"]), 9.0);
}

}  // namespace
}  // namespace silnet::aggregator
