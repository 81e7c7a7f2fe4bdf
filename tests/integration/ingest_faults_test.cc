// Faults the aggregator's ingest survives, with real processes over loopback DDS: a node
// whose stream stalls is reported (and resumes, losing nothing); a store that cannot write
// (a full disk, simulated with a file-size limit on the aggregator process) is reported and
// catches up through re-send requests once it writes again; duplicated, out-of-order and
// malformed samples from a misbehaving publisher are rejected and counted exactly.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <thread>

#include "shared/io/session_log_reader.h"
#include "tests/support/child_process.h"
#include "tests/support/eventually.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using testing::Eventually;

const std::filesystem::path kBin = SILNET_BINARY_DIR;
const std::filesystem::path kSim = kBin / "sim/silnet-sim";
const std::filesystem::path kNode = kBin / "node/silnet-node";
const std::filesystem::path kAggregator = kBin / "aggregator/silnet-aggregator";
const std::filesystem::path kProbe = kBin / "tests/silnet-dds-probe";
constexpr uint64_t kFrames = 150;

// A 2-camera masks-only dataset shared by the tests of this file.
const std::filesystem::path& Dataset() {
  static testing::TempDir dir("silnet-ingest-faults");
  static const std::filesystem::path dataset = [] {
    const std::filesystem::path out = dir / "dataset";
    testing::ChildProcess sim(kSim,
                              {"generate", "-o", out.string(), "--cameras", "2", "--frames",
                               std::to_string(kFrames), "--seed", "3", "--masks-only"},
                              dir.path());
    EXPECT_EQ(sim.Wait(seconds(300)), std::optional<int>(0)) << sim.Stderr();
    return out;
  }();
  return dataset;
}

std::unique_ptr<testing::ChildProcess> StartNode(const testing::TempDir& work,
                                                 const std::string& speed) {
  return std::make_unique<testing::ChildProcess>(
      kNode,
      std::vector<std::string>{"--camera-id", "cam00", "--source",
                               "sim-masks:" + (Dataset() / "cam00").string(), "--speed", speed,
                               "--linger", "6"},
      work.path());
}

// Hull frame indices held for cam00's only session, checked dense 0..kFrames-1.
void ExpectEveryFrameHeld(const std::filesystem::path& sessions_dir) {
  const auto sessions = ReadSessionLog(SessionLogPath(sessions_dir, "cam00"));
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_EQ(sessions[0].hulls.size(), kFrames);
  for (uint64_t i = 0; i < kFrames; ++i)
    ASSERT_EQ(sessions[0].hulls[i].frame_index, i);
}

// cam00's frames held by the ingest whose status file is `path` (0 until it is written).
double FramesHeld(const std::filesystem::path& path) {
  cv::FileStorage status(path.string(), cv::FileStorage::READ);
  if (!status.isOpened() || status["cameras"].size() == 0) return 0;
  return static_cast<double>(status["cameras"][0]["frames_held"]);
}

TEST(IngestFaults, AStalledNodeIsReportedAndLosesNothing) {
  testing::TempDir work;
  testing::ChildProcess aggregator(kAggregator,
                                   {"ingest", "-o", (work / "agg").string(), "--idle-exit", "4",
                                    "--stall-after", "1.5", "--status-every", "1"},
                                   work.path());
  std::this_thread::sleep_for(milliseconds(500));
  auto node = StartNode(work, "1");
  // Stopped once its stream runs (on a loaded machine the node may take seconds to start).
  Eventually([&] { return FramesHeld(work / "agg/ingest_summary.yaml") > 10.0; }, seconds(30));
  node->Signal(SIGSTOP);
  // The status file written while ingest runs shows the node silent (no NodeStatus for 3 s)
  // and its stream stalled (no frame for 1.5 s); the file is written every second and polled,
  // for a loaded machine.
  cv::FileStorage status;
  const auto silent = [&] {
    const cv::FileNode c = status["cameras"][0];
    return static_cast<int>(c["stalled"]) == 1 && static_cast<int>(c["node_alive"]) == 0;
  };
  Eventually(
      [&] {
        status.open((work / "agg/ingest_summary.yaml").string(), cv::FileStorage::READ);
        return status.isOpened() && silent();
      },
      seconds(30), milliseconds(500));
  ASSERT_TRUE(status.isOpened());
  const cv::FileNode camera = status["cameras"][0];
  EXPECT_EQ(static_cast<std::string>(camera["id"]), "cam00");
  EXPECT_EQ(static_cast<int>(camera["stalled"]), 1);
  EXPECT_EQ(static_cast<int>(camera["node_alive"]), 0);
  EXPECT_GT(static_cast<double>(camera["seconds_since_last_frame"]), 1.5);
  EXPECT_GT(static_cast<double>(camera["frames_held"]), 10.0);
  status.release();
  node->Signal(SIGCONT);
  ASSERT_EQ(node->Wait(seconds(60)), std::optional<int>(0)) << node->Stderr();
  ASSERT_EQ(aggregator.Wait(seconds(60)), std::optional<int>(0)) << aggregator.Stderr();
  const std::string log = aggregator.Stderr();
  EXPECT_NE(log.find("cam00 stalled: no frame for"), std::string::npos) << log;
  EXPECT_NE(log.find("STALLED"), std::string::npos) << log;
  EXPECT_NE(log.find("cam00 resumed after a stall"), std::string::npos) << log;
  EXPECT_NE(aggregator.Stdout().find(" 0 missing,"), std::string::npos) << aggregator.Stdout();
  EXPECT_NE(aggregator.Stdout().find(", 1 stalls"), std::string::npos) << aggregator.Stdout();
  ExpectEveryFrameHeld(work / "agg/sessions");
}

TEST(IngestFaults, AStoreThatCannotWriteReportsItAndCatchesUpWhenItCan) {
  testing::TempDir work;
  testing::ChildProcess aggregator(
      kAggregator, {"ingest", "-o", (work / "agg").string(), "--idle-exit", "4"}, work.path());
  // Room for the log headers and a few frames only: every later write fails with EFBIG, as
  // writes to a full disk fail with ENOSPC (the store handles both alike).
  const rlimit tight{16 * 1024, RLIM_INFINITY};
  ASSERT_EQ(prlimit(aggregator.pid(), RLIMIT_FSIZE, &tight, nullptr), 0);
  std::this_thread::sleep_for(milliseconds(500));
  auto node = StartNode(work, "2");
  // The limit is lifted once the store has failed, not after a time: on a loaded machine the
  // node may take seconds to start.
  Eventually(
      [&] { return aggregator.Stderr().find("session store cannot write") != std::string::npos; },
      seconds(60), milliseconds(100));
  const rlimit open{RLIM_INFINITY, RLIM_INFINITY};
  ASSERT_EQ(prlimit(aggregator.pid(), RLIMIT_FSIZE, &open, nullptr), 0);
  ASSERT_EQ(node->Wait(seconds(60)), std::optional<int>(0)) << node->Stderr();
  ASSERT_EQ(aggregator.Wait(seconds(60)), std::optional<int>(0)) << aggregator.Stderr();
  const std::string log = aggregator.Stderr();
  EXPECT_NE(log.find("session store cannot write"), std::string::npos) << log;
  EXPECT_NE(log.find("session store writes again"), std::string::npos) << log;
  EXPECT_EQ(aggregator.Stdout().find(" 0 store failures"), std::string::npos)
      << aggregator.Stdout();
  EXPECT_NE(aggregator.Stdout().find(" 0 missing,"), std::string::npos) << aggregator.Stdout();
  ExpectEveryFrameHeld(work / "agg/sessions");
}

TEST(IngestFaults, DuplicateOutOfOrderAndMalformedSamplesAreRejectedAndCounted) {
  testing::TempDir work;
  testing::ChildProcess aggregator(
      kAggregator, {"ingest", "-o", (work / "agg").string(), "--idle-exit", "2"}, work.path());
  testing::ChildProcess probe(kProbe, {"misbehave", "bad00"}, work.path());
  ASSERT_EQ(probe.Wait(seconds(40)), std::optional<int>(0)) << probe.Stderr();
  ASSERT_EQ(aggregator.Wait(seconds(40)), std::optional<int>(0)) << aggregator.Stderr();
  // 19 samples: 15 well formed (13 frames held, 0..12, and 2 duplicates; 1 out of order), 3
  // malformed with the camera's id and 1 without any.
  EXPECT_NE(aggregator.Stdout().find("ingest: 15 samples received, 13 frames held, 0 missing, 2 "
                                     "duplicates, 4 malformed"),
            std::string::npos)
      << aggregator.Stdout();
  const std::string summary = [&] {
    std::ifstream in(work / "agg/ingest_summary.yaml");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }();
  EXPECT_NE(summary.find("out_of_order: 1."), std::string::npos) << summary;
  EXPECT_NE(summary.find("malformed: 3."), std::string::npos) << summary;
  EXPECT_NE(summary.find("malformed_without_camera: 1."), std::string::npos) << summary;
  const auto sessions = ReadSessionLog(SessionLogPath(work / "agg/sessions", "bad00"));
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_EQ(sessions[0].hulls.size(), 13u);
  for (uint64_t i = 0; i < 13; ++i)
    EXPECT_EQ(sessions[0].hulls[i].frame_index, i);
}

}  // namespace
}  // namespace silnet
