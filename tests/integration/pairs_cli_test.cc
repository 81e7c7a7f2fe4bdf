// silnet-aggregator pairs on a simulated dataset folder and on an ingested session store:
// pairs.yaml agrees with the ground truth; overlays and matches are written; with the
// nodes' timestamps the offset search is narrowed and still right; bad input is refused.

#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "aggregator/pairwise/pairwise_job.h"
#include "shared/geometry/epipolar.h"
#include "shared/io/calibration_yaml.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::seconds;

const std::filesystem::path kBin = SILNET_BINARY_DIR;

// Checks every ok pair of pairs.yaml against the ground truth; returns how many were ok.
size_t CheckAgainstTruth(const std::filesystem::path& pairs_yaml,
                         const std::filesystem::path& truth) {
  const auto cameras = LoadCalibration(truth);
  const auto pairs = aggregator::ReadPairsYaml(pairs_yaml);
  size_t ok = 0;
  for (const auto& p : pairs) {
    if (p.status != aggregator::PairStatus::kOk) {
      EXPECT_FALSE(p.reason.empty());
      continue;
    }
    ++ok;
    const CameraModel& ci = *std::find_if(cameras.begin(), cameras.end(),
                                          [&](const auto& c) { return c.id == p.camera_i; });
    const CameraModel& cj = *std::find_if(cameras.begin(), cameras.end(),
                                          [&](const auto& c) { return c.id == p.camera_j; });
    EXPECT_NEAR(p.offset, ci.time_offset - cj.time_offset, 0.2) << p.camera_i << "-" << p.camera_j;
    // The estimate transfers points like the truth, over the capture area.
    std::vector<double> distances;
    for (double x = -1.0; x <= 1.0; x += 0.25) {
      for (double z = 0.2; z <= 1.8; z += 0.4) {
        const Eigen::Vector3d X(x, 0.5 * x, z);
        const auto pi = ci.Project(X), pj = cj.Project(X);
        if (pi && pj) distances.push_back(SymmetricEpipolarDistance(p.F, *pi, *pj));
      }
    }
    std::sort(distances.begin(), distances.end());
    EXPECT_LT(distances[distances.size() / 2], 1.0) << p.camera_i << "-" << p.camera_j;
  }
  return ok;
}

TEST(PairsCli, DatasetFolderInPairsYamlOut) {
  testing::TempDir work;
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", (work / "data").string(), "--cameras", "4",
                             "--frames", "300", "--masks-only", "--seed", "9"},
                            work.path());
  ASSERT_EQ(sim.Wait(seconds(120)), std::optional<int>(0)) << sim.Stderr();
  testing::ChildProcess pairs(kBin / "aggregator/silnet-aggregator",
                              {"pairs", (work / "data").string(), "-o", (work / "out").string()},
                              work.path());
  ASSERT_EQ(pairs.Wait(seconds(300)), std::optional<int>(0)) << pairs.Stderr();
  EXPECT_GE(CheckAgainstTruth(work / "out/pairs.yaml", work / "data/ground_truth.yaml"), 5u);
  EXPECT_TRUE(std::filesystem::exists(work / "out/overlays/cam00-cam01.png") ||
              std::filesystem::exists(work / "out/overlays/cam00-cam02.png"));
  EXPECT_FALSE(std::filesystem::is_empty(work / "out/matches"));
  EXPECT_NE(pairs.Stdout().find("ok in"), std::string::npos);
}

TEST(PairsCli, AnIngestedSessionWithTimestampPriors) {
  testing::TempDir work;
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", (work / "data").string(), "--cameras", "3",
                             "--frames", "240", "--masks-only", "--seed", "6"},
                            work.path());
  ASSERT_EQ(sim.Wait(seconds(120)), std::optional<int>(0)) << sim.Stderr();
  testing::ChildProcess ingest(kBin / "aggregator/silnet-aggregator",
                               {"ingest", "-o", (work / "agg").string(), "--idle-exit", "3"},
                               work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // Three nodes replay the simulated cameras live from one shared start time.
  const std::string start = std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::system_clock::now().time_since_epoch())
                                               .count() +
                                           1'000'000'000LL);
  std::vector<std::unique_ptr<testing::ChildProcess>> nodes;
  for (const char* camera : {"cam00", "cam01", "cam02"}) {
    nodes.push_back(std::make_unique<testing::ChildProcess>(
        kBin / "node/silnet-node",
        std::vector<std::string>{"--camera-id", camera, "--source",
                                 "sim-masks:" + (work / "data" / camera).string(), "--start-at",
                                 start, "--speed", "3", "--linger", "2"},
        work.path()));
  }
  for (auto& node : nodes)
    ASSERT_EQ(node->Wait(seconds(120)), std::optional<int>(0)) << node->Stderr();
  ASSERT_EQ(ingest.Wait(seconds(60)), std::optional<int>(0)) << ingest.Stderr();
  testing::ChildProcess pairs(kBin / "aggregator/silnet-aggregator",
                              {"pairs", (work / "agg").string(), "-o", (work / "out").string(),
                               "--use-timestamps", "--overlays", "none"},
                              work.path());
  ASSERT_EQ(pairs.Wait(seconds(300)), std::optional<int>(0)) << pairs.Stderr();
  EXPECT_GE(CheckAgainstTruth(work / "out/pairs.yaml", work / "data/ground_truth.yaml"), 2u);
}

TEST(PairsCli, RefusesInputItCannotUse) {
  testing::TempDir work;
  std::filesystem::create_directories(work / "empty");
  testing::ChildProcess empty(kBin / "aggregator/silnet-aggregator",
                              {"pairs", (work / "empty").string(), "-o", (work / "out").string()},
                              work.path());
  EXPECT_EQ(empty.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(empty.Stderr().find("neither session logs"), std::string::npos) << empty.Stderr();
  testing::ChildProcess missing(kBin / "aggregator/silnet-aggregator",
                                {"pairs", (work / "nope").string(), "-o", (work / "out").string()},
                                work.path());
  EXPECT_EQ(missing.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(missing.Stderr().find("not a folder"), std::string::npos) << missing.Stderr();
}

}  // namespace
}  // namespace silnet
