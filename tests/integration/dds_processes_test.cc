// Two processes over loopback DDS: silnet-dds-probe publishes, this test receives, and a
// probe in another domain receives nothing.

#include <gtest/gtest.h>

#include <sstream>
#include <thread>

#include "shared/dds/topics.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

const std::filesystem::path kProbe =
    std::filesystem::path(SILNET_BINARY_DIR) / "tests/silnet-dds-probe";

TEST(DdsProcesses, ASampleWrittenByOneProcessIsReceivedByAnother) {
  testing::TempDir logs;
  dds::Participant participant;
  dds::Topic<silnet_wire_HullFrame> topic(participant);
  dds::Reader<silnet_wire_HullFrame> reader(topic);
  testing::ChildProcess publisher(kProbe, {"publish", "300"}, logs.path());
  std::vector<uint64_t> indices;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (indices.size() < 300 && std::chrono::steady_clock::now() < deadline) {
    reader.WaitForData(std::chrono::milliseconds(100));
    reader.Take([&](const silnet_wire_HullFrame& f, const dds_sample_info_t&) {
      EXPECT_EQ(dds::ReadBoundedString(f.camera_id), "probe");
      indices.push_back(f.frame_index);
    });
  }
  ASSERT_EQ(publisher.Wait(std::chrono::seconds(30)), std::optional<int>(0)) << publisher.Stderr();
  ASSERT_EQ(indices.size(), 300u);
  for (uint64_t i = 0; i < indices.size(); ++i)
    EXPECT_EQ(indices[i], i);
}

TEST(DdsProcesses, AProcessInAnotherDomainSeesNothing) {
  testing::TempDir logs;
  testing::ChildProcess same(kProbe, {"receive", "10", "20"}, logs.path());
  testing::ChildProcess other(kProbe, {"receive", "1", "4"}, logs.path(),
                              {{"SILNET_DDS_DOMAIN", "232"}});
  dds::Participant participant;
  dds::Topic<silnet_wire_HullFrame> topic(participant);
  dds::Writer<silnet_wire_HullFrame> writer(topic);
  ASSERT_TRUE(writer.WaitForReaders(1, std::chrono::seconds(20)));
  for (uint64_t i = 0; i < 10; ++i) {
    silnet_wire_HullFrame f{};
    dds::CopyBoundedString("cam00", f.camera_id, "camera id");
    f.frame_index = i;
    ASSERT_TRUE(writer.Write(f));
  }
  ASSERT_TRUE(writer.WaitForAcknowledgements(std::chrono::seconds(10)));
  EXPECT_EQ(same.Wait(std::chrono::seconds(25)), std::optional<int>(0)) << same.Stderr();
  std::istringstream lines(same.Stdout());
  uint64_t value = 0, expected = 0;
  while (lines >> value)
    EXPECT_EQ(value, expected++);
  EXPECT_EQ(expected, 10u);
  EXPECT_EQ(other.Wait(std::chrono::seconds(10)), std::optional<int>(3)) << other.Stdout();
  EXPECT_TRUE(other.Stdout().empty());
  // Once the same-domain reader has gone, nothing is matched: the other never was.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (writer.Counters().matched_readers > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(writer.Counters().matched_readers, 0u);
}

}  // namespace
}  // namespace silnet
