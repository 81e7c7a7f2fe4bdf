#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "shared/dds/topics.h"

namespace silnet::dds {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

silnet_wire_HullFrame MakeFrame(const std::string& camera, uint64_t index,
                                std::vector<uint8_t>* payload) {
  silnet_wire_HullFrame frame{};
  CopyBoundedString(camera, frame.camera_id, "camera id");
  frame.frame_index = index;
  frame.capture_time_ns = static_cast<int64_t>(index) * 33333333;
  frame.image_width = 640;
  frame.image_height = 480;
  frame.flags = silnet_wire_FRAME_CLIPPED;
  payload->assign(1 + index % 300, static_cast<uint8_t>(index));
  frame.hull._buffer = payload->data();
  frame.hull._length = static_cast<uint32_t>(payload->size());
  frame.hull._maximum = frame.hull._length;
  frame.hull._release = false;
  return frame;
}

// Takes until `count` samples arrived or `timeout` passed.
std::vector<uint64_t> Receive(Reader<silnet_wire_HullFrame>& reader, size_t count,
                              milliseconds timeout, bool* payload_ok = nullptr) {
  std::vector<uint64_t> indices;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (indices.size() < count && std::chrono::steady_clock::now() < deadline) {
    reader.WaitForData(milliseconds(50));
    reader.Take([&](const silnet_wire_HullFrame& f, const dds_sample_info_t&) {
      indices.push_back(f.frame_index);
      const bool ok =
          f.hull._length == 1 + f.frame_index % 300 &&
          (f.hull._length == 0 || f.hull._buffer[0] == static_cast<uint8_t>(f.frame_index));
      if (payload_ok != nullptr && !ok) *payload_ok = false;
    });
  }
  return indices;
}

TEST(Dds, SamplesArriveInOrderExactlyOnceWithTheirPayload) {
  Participant participant;
  Topic<silnet_wire_HullFrame> topic(participant);
  Reader<silnet_wire_HullFrame> reader(topic);
  Writer<silnet_wire_HullFrame> writer(topic);
  ASSERT_TRUE(writer.WaitForReaders(1, seconds(10)));
  std::vector<uint8_t> payload;
  for (uint64_t i = 0; i < 500; ++i)
    ASSERT_TRUE(writer.Write(MakeFrame("cam00", i, &payload)));
  bool payload_ok = true;
  const auto indices = Receive(reader, 500, seconds(20), &payload_ok);
  ASSERT_EQ(indices.size(), 500u);
  for (uint64_t i = 0; i < 500; ++i)
    EXPECT_EQ(indices[i], i);
  EXPECT_TRUE(payload_ok);
  EXPECT_EQ(reader.Counters().samples_lost, 0u);
  EXPECT_EQ(reader.Counters().samples_rejected, 0u);
  EXPECT_EQ(writer.Counters().matched_readers, 1u);
}

TEST(Dds, LatchedTopicsReachLateReaders) {
  Participant participant;
  Topic<silnet_wire_CameraInfo> topic(participant);
  Writer<silnet_wire_CameraInfo> writer(topic);
  for (int version = 0; version < 3; ++version) {
    silnet_wire_CameraInfo info{};
    CopyBoundedString("cam07", info.camera_id, "camera id");
    info.image_width = static_cast<uint16_t>(600 + version);
    ASSERT_TRUE(writer.Write(info));
  }
  Reader<silnet_wire_CameraInfo> late(topic);
  std::vector<int> widths;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (widths.empty() && std::chrono::steady_clock::now() < deadline) {
    late.WaitForData(milliseconds(50));
    late.Take([&](const silnet_wire_CameraInfo& i, const dds_sample_info_t&) {
      widths.push_back(i.image_width);
    });
  }
  EXPECT_EQ(widths, std::vector<int>{602});
}

TEST(Dds, DifferentDomainsDoNotSeeEachOther) {
  DomainConfig mine = DomainConfig::FromEnvironment();
  DomainConfig other = mine;
  other.domain_id = 231;  // never handed to a test by silnet_add_test
  Participant here(mine), there(other);
  Topic<silnet_wire_HullFrame> topic_here(here), topic_there(there);
  Reader<silnet_wire_HullFrame> reader_here(topic_here), reader_there(topic_there);
  Writer<silnet_wire_HullFrame> writer(topic_here);
  ASSERT_TRUE(writer.WaitForReaders(1, seconds(10)));
  std::vector<uint8_t> payload;
  for (uint64_t i = 0; i < 20; ++i)
    ASSERT_TRUE(writer.Write(MakeFrame("cam01", i, &payload)));
  EXPECT_EQ(Receive(reader_here, 20, seconds(10)).size(), 20u);
  EXPECT_TRUE(Receive(reader_there, 1, milliseconds(1500)).empty());
  EXPECT_EQ(reader_there.Counters().matched_writers, 0u);
}

TEST(Dds, BoundedStringsAreCheckedNotTruncated) {
  silnet_wire_HullFrame frame{};
  EXPECT_THROW(CopyBoundedString(std::string(40, 'x'), frame.camera_id, "camera id"), InputError);
  CopyBoundedString(std::string(31, 'y'), frame.camera_id, "camera id");
  EXPECT_EQ(ReadBoundedString(frame.camera_id), std::string(31, 'y'));
  std::memset(frame.camera_id, 'z', sizeof(frame.camera_id));  // no terminator
  EXPECT_EQ(ReadBoundedString(frame.camera_id).size(), sizeof(frame.camera_id));
}

TEST(DomainConfig, ReadsTheEnvironmentAndRejectsBadValues) {
  const DomainConfig config = DomainConfig::FromEnvironment();
  EXPECT_TRUE(config.loopback);  // silnet_add_test runs every test on loopback
  EXPECT_NE(config.ToXml().find("127.0.0.1"), std::string::npos);
  EXPECT_NE(config.ToXml().find("<ParticipantIndex>auto</ParticipantIndex>"), std::string::npos);
  const std::string saved = std::getenv("SILNET_DDS_DOMAIN");
  setenv("SILNET_DDS_DOMAIN", "999", 1);
  EXPECT_THROW(DomainConfig::FromEnvironment(), InputError);
  setenv("SILNET_DDS_DOMAIN", "12abc", 1);
  EXPECT_THROW(DomainConfig::FromEnvironment(), InputError);
  setenv("SILNET_DDS_DOMAIN", saved.c_str(), 1);
  DomainConfig bad;
  bad.discovery_tag = "a<b";
  EXPECT_THROW(bad.ToXml(), InputError);
}

TEST(Participant, AConflictingConfigurationForAnOpenDomainIsAnError) {
  DomainConfig mine = DomainConfig::FromEnvironment();
  Participant first(mine);
  DomainConfig conflicting = mine;
  conflicting.discovery_tag += "-different";
  EXPECT_THROW(Participant{conflicting}, DdsError);
}

}  // namespace
}  // namespace silnet::dds
