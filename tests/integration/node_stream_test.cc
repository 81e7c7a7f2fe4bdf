// A real silnet-node publishing a simulated 300-frame feed to a real silnet-aggregator ingest
// in another process over loopback DDS: every frame arrives exactly once and in order; a
// subscriber killed and restarted mid-stream loses no frame (DDS history and the node's
// re-send of its local history fill the gap); a node killed and restarted (after the
// aggregator was killed and restarted) loses no frame it recorded: the restarted node
// re-sends the old session from its recording; bad input gives clear
// errors or flagged frames.

#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "shared/io/session_log_reader.h"
#include "shared/record/record_log.h"
#include "silnet.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::seconds;

const std::filesystem::path kBin = SILNET_BINARY_DIR;
const std::filesystem::path kSim = kBin / "sim/silnet-sim";
const std::filesystem::path kNode = kBin / "node/silnet-node";
const std::filesystem::path kAggregator = kBin / "aggregator/silnet-aggregator";

// A 2-camera 300-frame simulated dataset shared by the tests of this file.
const std::filesystem::path& Dataset() {
  static testing::TempDir dir("silnet-node-stream");
  static const std::filesystem::path dataset = [] {
    const std::filesystem::path out = dir / "dataset";
    testing::ChildProcess sim(
        kSim, {"generate", "-o", out.string(), "--cameras", "2", "--frames", "300", "--seed", "11"},
        dir.path());
    EXPECT_EQ(sim.Wait(seconds(300)), std::optional<int>(0)) << sim.Stderr();
    return out;
  }();
  return dataset;
}

std::vector<SessionFrames> Sessions(const std::filesystem::path& store, const std::string& camera) {
  return ReadSessionLog(SessionLogPath(store, camera));
}

// Hull frames of the first session in `log` so far (0 while the log is not there or not
// readable yet: it may be being written).
size_t FirstSessionHulls(const std::filesystem::path& log) {
  try {
    const std::vector<SessionFrames> sessions = ReadSessionLog(log);
    return sessions.empty() ? 0 : sessions[0].hulls.size();
  } catch (const std::exception&) {
    return 0;
  }
}

// Waits up to `timeout` for the first session in `log` to hold at least `count` hull frames;
// returns how many it holds then.
size_t WaitForHulls(const std::filesystem::path& log, size_t count, seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  size_t held = FirstSessionHulls(log);
  while (held < count && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    held = FirstSessionHulls(log);
  }
  return held;
}

// Hull frame indices in the order the store received them.
std::vector<uint64_t> ArrivalOrder(const std::filesystem::path& log) {
  RecordLogReader reader;
  EXPECT_TRUE(reader.Open(log).ok());
  std::vector<uint64_t> order;
  Record record;
  while (reader.Next(&record) == ReadStatus::kOk) {
    if (record.type != static_cast<uint16_t>(SessionRecordType::kHullFrame)) continue;
    FrameRecord frame;
    EXPECT_TRUE(ParseFrameRecord(record.payload, &frame, nullptr));
    order.push_back(frame.frame_index);
  }
  return order;
}

TEST(NodeStream, EveryFrameArrivesExactlyOnceAndInOrder) {
  testing::TempDir work;
  testing::ChildProcess aggregator(
      kAggregator, {"ingest", "-o", (work / "agg").string(), "--idle-exit", "3"}, work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // Lossless: a node sharing two cores with other tests falls behind and would drop frames
  // (published flagged, without contours), which is right for a camera but not this check.
  testing::ChildProcess node(
      kNode,
      {"--camera-id", "cam00", "--source", "sim:" + (Dataset() / "cam00").string(), "--speed", "2",
       "--lossless", "--linger", "2"},
      work.path());
  ASSERT_EQ(node.Wait(seconds(120)), std::optional<int>(0)) << node.Stderr();
  ASSERT_EQ(aggregator.Wait(seconds(60)), std::optional<int>(0)) << aggregator.Stderr();
  const std::filesystem::path store = work / "agg/sessions";
  std::printf("%s", aggregator.Stdout().c_str());
  const std::vector<uint64_t> order = ArrivalOrder(SessionLogPath(store, "cam00"));
  ASSERT_EQ(order.size(), 300u) << aggregator.Stdout();
  for (uint64_t i = 0; i < order.size(); ++i)
    ASSERT_EQ(order[i], i);
  const auto sessions = Sessions(store, "cam00");
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].contours.size(), 300u);
  for (size_t i = 0, j = 0; i < sessions[0].hulls.size(); ++i) {
    if (j < sessions[0].contours.size() && sessions[0].contours[j].frame_index == i) {
      ++j;
    } else {
      ADD_FAILURE() << "no contour of frame " << i << "\n" << aggregator.Stderr();
      break;
    }
  }
  EXPECT_EQ(sessions[0].info.source_kind, "sim");
  // After warm-up the silhouettes are real: non-empty, unflagged hulls.
  int good = 0;
  for (const FrameRecord& f : sessions[0].hulls)
    good += (f.flags & silnet_wire_FRAME_WARMUP) == 0 ? 1 : 0;
  EXPECT_GT(good, 50);
  EXPECT_NE(aggregator.Stdout().find("0 missing, 0 duplicates, 0 malformed"), std::string::npos)
      << aggregator.Stdout();
}

TEST(NodeStream, ASubscriberKilledAndRestartedMidStreamLosesNoFrame) {
  testing::TempDir work;
  const std::string out = (work / "agg").string();
  auto first = std::make_unique<testing::ChildProcess>(
      kAggregator, std::vector<std::string>{"ingest", "-o", out, "--status-every", "1"},
      work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // A short DDS history, so the restarted subscriber must ask the node to re-send.
  testing::ChildProcess node(
      kNode,
      {"--camera-id", "cam01", "--source", "sim:" + (Dataset() / "cam01").string(), "--speed", "2",
       "--linger", "8", "--dds-history", "10", "--record", (work / "node-recording").string()},
      work.path());
  std::this_thread::sleep_for(seconds(2));
  first->Kill(SIGKILL);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  testing::ChildProcess second(kAggregator, {"ingest", "-o", out, "--idle-exit", "3"}, work.path());
  ASSERT_EQ(node.Wait(seconds(120)), std::optional<int>(0)) << node.Stderr();
  ASSERT_EQ(second.Wait(seconds(60)), std::optional<int>(0)) << second.Stderr();
  const auto sessions = Sessions(work / "agg/sessions", "cam01");
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_EQ(sessions[0].hulls.size(), 300u) << second.Stdout() << second.Stderr();
  for (uint64_t i = 0; i < 300; ++i)
    EXPECT_EQ(sessions[0].hulls[i].frame_index, i);
  cv::FileStorage summary((work / "agg/ingest_summary.yaml").string(), cv::FileStorage::READ);
  EXPECT_EQ(static_cast<double>(summary["cameras"][0]["missing"]), 0.0);
  // The node's own crash-safe recording holds the whole session too.
  const auto recorded = ReadSessionLog(SessionLogPath(work / "node-recording", "cam01"));
  ASSERT_EQ(recorded.size(), 1u);
  EXPECT_EQ(recorded[0].hulls.size(), 300u);
}

TEST(NodeStream, ANodeKilledAndRestartedLosesNoRecordedFrame) {
  testing::TempDir work;
  const std::vector<std::string> ingest{"ingest", "-o", (work / "agg").string(), "--idle-exit",
                                        "4"};
  auto first_aggregator = std::make_unique<testing::ChildProcess>(kAggregator, ingest, work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const std::vector<std::string> node_args{
      "--camera-id", "cam00", "--source", "sim:" + (Dataset() / "cam00").string(), "--speed", "1",
      "--linger",    "6",     "--record", (work / "node-recording").string()};
  auto first_node = std::make_unique<testing::ChildProcess>(kNode, node_args, work.path());
  // The aggregator dies first, then the node: frames of the first session exist only in the
  // node's recording. Each dies once the frames are there, not after a time: on a busy
  // machine a node may take seconds to start (the restarted aggregator learns of the first
  // session from the frames it stored).
  const size_t stored_first =
      WaitForHulls(SessionLogPath(work / "agg/sessions", "cam00"), 30, seconds(60));
  ASSERT_GE(stored_first, 30u) << first_node->Stderr();
  first_aggregator->Kill(SIGKILL);
  ASSERT_GE(WaitForHulls(SessionLogPath(work / "node-recording", "cam00"), stored_first + 20,
                         seconds(60)),
            stored_first + 20)
      << first_node->Stderr();
  first_node->Kill(SIGKILL);
  testing::ChildProcess aggregator(kAggregator, ingest, work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  testing::ChildProcess node(kNode, node_args, work.path());
  ASSERT_EQ(node.Wait(seconds(120)), std::optional<int>(0)) << node.Stderr();
  ASSERT_EQ(aggregator.Wait(seconds(60)), std::optional<int>(0)) << aggregator.Stderr();
  EXPECT_NE(node.Stderr().find("recorded frames of session"), std::string::npos) << node.Stderr();
  // Every frame the killed node recorded reached the store, and the new session is whole.
  const auto recorded = ReadSessionLog(SessionLogPath(work / "node-recording", "cam00"));
  const auto stored = Sessions(work / "agg/sessions", "cam00");
  ASSERT_EQ(recorded.size(), 2u);
  ASSERT_EQ(stored.size(), 2u) << aggregator.Stderr();
  EXPECT_GT(recorded[0].hulls.size(), 30u);
  EXPECT_LT(recorded[0].hulls.size(), 300u);
  ASSERT_EQ(stored[0].hulls.size(), recorded[0].hulls.size()) << aggregator.Stderr();
  for (size_t i = 0; i < recorded[0].hulls.size(); ++i)
    EXPECT_EQ(stored[0].hulls[i].frame_index, recorded[0].hulls[i].frame_index);
  EXPECT_EQ(stored[0].contours.size(), recorded[0].contours.size());
  ASSERT_EQ(stored[1].hulls.size(), 300u);
  for (uint64_t i = 0; i < 300; ++i)
    EXPECT_EQ(stored[1].hulls[i].frame_index, i);
}

TEST(NodeStream, ALateSubscriberGetsTheFramesItMissedReSent) {
  testing::TempDir work;
  // The DDS history keeps 10 frames; everything older must come from the node's own history.
  testing::ChildProcess node(
      kNode,
      {"--camera-id", "cam00", "--source", "sim:" + (Dataset() / "cam00").string(), "--speed", "2",
       "--linger", "10", "--dds-history", "10", "--record", (work / "node-recording").string()},
      work.path());
  // The subscriber starts once the node has published 150 frames, not after a time: on a busy
  // machine the node may take seconds to start (after a 3 s sleep it had re-sent only 95).
  ASSERT_GE(WaitForHulls(SessionLogPath(work / "node-recording", "cam00"), 150, seconds(60)), 150u)
      << node.Stderr();
  testing::ChildProcess aggregator(
      kAggregator, {"ingest", "-o", (work / "agg").string(), "--idle-exit", "3"}, work.path());
  ASSERT_EQ(aggregator.Wait(seconds(120)), std::optional<int>(0)) << aggregator.Stderr();
  node.Kill(SIGTERM);
  const auto sessions = Sessions(work / "agg/sessions", "cam00");
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_EQ(sessions[0].hulls.size(), 300u) << aggregator.Stdout();
  for (uint64_t i = 0; i < 300; ++i)
    EXPECT_EQ(sessions[0].hulls[i].frame_index, i);
  cv::FileStorage summary((work / "agg/ingest_summary.yaml").string(), cv::FileStorage::READ);
  const cv::FileNode camera = summary["cameras"][0];
  EXPECT_EQ(static_cast<double>(camera["missing"]), 0.0);
  EXPECT_GT(static_cast<double>(camera["resend_requests"]), 0.0);
  EXPECT_GT(static_cast<double>(camera["resent_received"]), 100.0);
}

TEST(NodeStream, SigtermStopsTheNodeCleanlyWithItsRecordingFlushed) {
  testing::TempDir work;
  testing::ChildProcess node(
      kNode,
      {"--camera-id", "cam00", "--source", "sim:" + (Dataset() / "cam00").string(), "--record",
       (work / "rec").string()},
      work.path());
  std::this_thread::sleep_for(seconds(2));
  node.Signal(SIGTERM);
  ASSERT_EQ(node.Wait(seconds(20)), std::optional<int>(0)) << node.Stderr();
  SessionReadReport report;
  const auto sessions = ReadSessionLog(SessionLogPath(work / "rec", "cam00"), &report);
  EXPECT_FALSE(report.torn_tail);
  EXPECT_TRUE(report.problem.empty()) << report.problem;
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_GT(sessions[0].hulls.size(), 10u);
  ASSERT_LT(sessions[0].hulls.size(), 300u);
  for (uint64_t i = 0; i < sessions[0].hulls.size(); ++i)
    EXPECT_EQ(sessions[0].hulls[i].frame_index, i);
  EXPECT_NE(node.Stderr().find("published"), std::string::npos);
}

TEST(NodeStream, BadInputGivesClearErrorsOrFlaggedFrames) {
  testing::TempDir work;
  // Unreadable sources and malformed options: exit code 2 and a message naming the problem.
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--camera-id", "c", "--source", "images:/no/such/folder"}, "/no/such/folder"},
      {{"--camera-id", "c", "--source", "v4l2:/dev/no-such-video"}, "/dev/no-such-video"},
      {{"--camera-id", "c", "--source", "video:/no/such.mp4"}, "/no/such.mp4"},
      {{"--camera-id", "c", "--source", "webcam0"}, "kind:location"},
      {{"--camera-id", "c", "--source", "images:/tmp", "--set", "threshold_sigmas=-1"},
       "threshold_sigmas"},
      {{"--camera-id", "c", "--source", "images:/tmp", "--set", "no_such=1"}, "no_such"},
      {{"--camera-id", std::string(40, 'x'), "--source", "images:/tmp"}, "31 characters"},
  };
  for (const Case& c : cases) {
    testing::ChildProcess node(kNode, c.args, work.path());
    EXPECT_EQ(node.Wait(seconds(30)), std::optional<int>(2)) << c.message;
    EXPECT_NE(node.Stderr().find(c.message), std::string::npos) << node.Stderr();
  }
  std::ofstream(work / "bad.toml") << "camera-id = \"c\"\nsource = 42\nno-such-option = 1\n";
  testing::ChildProcess bad_config(kNode, {"--config", (work / "bad.toml").string()}, work.path());
  EXPECT_NE(bad_config.Wait(seconds(30)), std::optional<int>(0));
  EXPECT_FALSE(bad_config.Stderr().empty());

  // Mask input with an empty mask, an all-white mask, a wrong-size mask and a corrupt file.
  const std::filesystem::path masks = work / "masks";
  std::filesystem::create_directories(masks);
  cv::Mat good(120, 160, CV_8U, cv::Scalar(0));
  good(cv::Rect(40, 30, 50, 60)).setTo(255);
  cv::imwrite((masks / "000000.png").string(), good);
  cv::imwrite((masks / "000001.png").string(), cv::Mat(120, 160, CV_8U, cv::Scalar(0)));
  cv::imwrite((masks / "000002.png").string(), cv::Mat(120, 160, CV_8U, cv::Scalar(255)));
  cv::imwrite((masks / "000003.png").string(), cv::Mat(60, 80, CV_8U, cv::Scalar(255)));
  std::ofstream(masks / "000004.png") << "not a png";
  cv::imwrite((masks / "000005.png").string(), good);
  testing::ChildProcess node(kNode,
                             {"--camera-id", "m0", "--source", "masks:" + masks.string(),
                              "--linger", "0", "--record", (work / "rec").string()},
                             work.path());
  ASSERT_EQ(node.Wait(seconds(60)), std::optional<int>(0)) << node.Stderr();
  const auto sessions = ReadSessionLog(SessionLogPath(work / "rec", "m0"));
  ASSERT_EQ(sessions.size(), 1u);
  const auto& hulls = sessions[0].hulls;
  ASSERT_EQ(hulls.size(), 6u);
  EXPECT_EQ(hulls[0].flags, 0u);
  EXPECT_TRUE(hulls[1].flags & silnet_wire_FRAME_EMPTY);
  EXPECT_TRUE(hulls[2].flags & silnet_wire_FRAME_SATURATED);
  EXPECT_TRUE(hulls[2].flags & silnet_wire_FRAME_CLIPPED);
  EXPECT_TRUE(hulls[3].flags & silnet_wire_FRAME_BAD_INPUT);
  EXPECT_TRUE(hulls[4].flags & silnet_wire_FRAME_BAD_INPUT);
  EXPECT_EQ(hulls[5].flags, 0u);
}

}  // namespace
}  // namespace silnet
