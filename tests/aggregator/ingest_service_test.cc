// The ingest against a hostile publisher: duplicated, out-of-order and malformed samples are
// rejected or stored once, and counted; gaps are asked for with re-send commands.

#include "aggregator/ingest/ingest_service.h"

#include <gtest/gtest.h>

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

TEST(IngestService, CountsDuplicatesOutOfOrderAndMalformedSamplesAndAsksForGaps) {
  testing::TempDir dir;
  IngestOptions options;
  options.store_dir = dir / "store";
  options.domain = dds::DomainConfig::FromEnvironment();
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

}  // namespace
}  // namespace silnet::aggregator
