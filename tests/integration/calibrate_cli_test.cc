// silnet-aggregator calibrate on simulated dataset folders: pairs -> sync -> calibration in
// one command; calibration.yaml agrees with the ground truth; COLMAP export, summary and the
// HTML report are written; the Calibration topic reaches a DDS reader; unusable input gives
// a clear exit code and message. (A network that calibrates only in part is tested in
// tests/aggregator/network_calibration_test.cc.)

#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <map>
#include <thread>

#include "aggregator/calibration/ground_truth_comparison.h"
#include "shared/dds/participant.h"
#include "shared/dds/topic.h"
#include "shared/dds/topics.h"
#include "shared/io/calibration_yaml.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::seconds;

const std::filesystem::path kBin = SILNET_BINARY_DIR;

void Generate(const testing::TempDir& work, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"generate", "-o", (work / "data").string(), "--masks-only"};
  args.insert(args.end(), extra.begin(), extra.end());
  testing::ChildProcess sim(kBin / "sim/silnet-sim", args, work.path());
  ASSERT_EQ(sim.Wait(seconds(180)), std::optional<int>(0)) << sim.Stderr();
}

size_t Lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);)
    n += line.empty() || line[0] == '#' ? 0 : 1;
  return n;
}

TEST(CalibrateCli, DatasetToCalibrationExportsReportAndDds) {
  testing::TempDir work;
  Generate(work, {"--cameras", "6", "--frames", "300", "--seed", "4"});
  dds::Participant participant;
  dds::Topic<silnet_wire_Calibration> topic(participant);
  dds::Reader<silnet_wire_Calibration> reader(topic);
  testing::ChildProcess calibrate(kBin / "aggregator/silnet-aggregator",
                                  {"calibrate", (work / "data").string(), "-o",
                                   (work / "out").string(), "--publish", "--linger", "30"},
                                  work.path());
  std::map<std::string, silnet_wire_Calibration> received;
  const auto deadline = std::chrono::steady_clock::now() + seconds(400);
  while (received.size() < 6 && std::chrono::steady_clock::now() < deadline &&
         !calibrate.Wait(std::chrono::milliseconds(0))) {
    reader.WaitForData(std::chrono::milliseconds(200));
    reader.Take([&](const silnet_wire_Calibration& c, const dds_sample_info_t&) {
      received[c.camera_id] = c;
    });
  }
  if (calibrate.running()) calibrate.Signal(SIGINT);  // ends the linger
  ASSERT_EQ(calibrate.Wait(seconds(60)), std::optional<int>(0)) << calibrate.Stderr();
  EXPECT_NE(calibrate.Stdout().find("6 of 6 cameras calibrated"), std::string::npos)
      << calibrate.Stdout();

  const auto truth = LoadCalibration(work / "data/ground_truth.yaml");
  const auto cameras = LoadCalibration(work / "out/calibration.yaml");
  ASSERT_EQ(cameras.size(), 6u);
  const aggregator::CalibrationErrors e =
      aggregator::CompareWithGroundTruth(cameras, std::vector<bool>(6, true), truth);
  // The command's plumbing, on a small capture (6 cameras, 10 s); the accuracy targets are
  // tested on full captures in tests/aggregator/network_calibration_test.cc.
  EXPECT_LE(e.median_focal_rel, 0.03);
  EXPECT_LE(e.median_rotation_deg, 1.0);
  EXPECT_LE(e.median_center_rel, 0.01);
  EXPECT_LE(e.max_offset_frames, 0.05);

  // The published calibrations are the file's, under one calibration id.
  ASSERT_EQ(received.size(), 6u);
  const uint64_t id = received.begin()->second.calibration_id;
  EXPECT_GT(id, 0u);
  for (const CameraModel& c : cameras) {
    ASSERT_TRUE(received.count(c.id)) << c.id;
    const silnet_wire_Calibration& w = received[c.id];
    EXPECT_EQ(w.calibration_id, id);
    EXPECT_NEAR(w.K[0], c.K(0, 0), 1e-9);
    EXPECT_NEAR(w.K[5], c.K(1, 2), 1e-9);
    EXPECT_NEAR(w.t[2], c.t.z(), 1e-9);
    EXPECT_NEAR(w.time_offset, c.time_offset, 1e-9);
  }

  EXPECT_EQ(Lines(work / "out/colmap/cameras.txt"), 6u);
  EXPECT_EQ(Lines(work / "out/colmap/images.txt"), 12u);  // two lines per image
  EXPECT_GT(Lines(work / "out/colmap/points3D.txt"), 1000u);
  for (const char* file :
       {"calibration_summary.yaml", "pairs.yaml", "report/report.html",
        "report/plots/camera_network.png", "report/plots/reprojection_errors.png",
        "report/plots/offsets_graph.png"}) {
    EXPECT_TRUE(std::filesystem::exists(work / "out" / file)) << file;
  }
}

TEST(CalibrateCli, TwoCamerasAreNotANetwork) {
  testing::TempDir work;
  Generate(work, {"--cameras", "2", "--frames", "60", "--seed", "3"});
  testing::ChildProcess calibrate(
      kBin / "aggregator/silnet-aggregator",
      {"calibrate", (work / "data").string(), "-o", (work / "out").string()}, work.path());
  EXPECT_EQ(calibrate.Wait(seconds(60)), std::optional<int>(2));
  EXPECT_NE(calibrate.Stderr().find("needs at least 3 cameras"), std::string::npos)
      << calibrate.Stderr();
}

TEST(CalibrateCli, RefusesInputItCannotUse) {
  testing::TempDir work;
  testing::ChildProcess missing(
      kBin / "aggregator/silnet-aggregator",
      {"calibrate", (work / "nope").string(), "-o", (work / "out").string()}, work.path());
  EXPECT_EQ(missing.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(missing.Stderr().find("not a folder"), std::string::npos) << missing.Stderr();

  Generate(work, {"--cameras", "3", "--frames", "60", "--seed", "2"});
  testing::ChildProcess distortion(
      kBin / "aggregator/silnet-aggregator",
      {"calibrate", (work / "data").string(), "-o", (work / "out").string(), "--distortion", "k9"},
      work.path());
  EXPECT_EQ(distortion.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(distortion.Stderr().find("--distortion must be"), std::string::npos)
      << distortion.Stderr();

  // An intrinsics file that lacks a camera of the input.
  auto partial = LoadCalibration(work / "data/ground_truth.yaml");
  partial.pop_back();
  SaveCalibration(work / "partial.yaml", partial);
  testing::ChildProcess intrinsics(
      kBin / "aggregator/silnet-aggregator",
      {"calibrate", (work / "data").string(), "-o", (work / "out").string(), "--intrinsics",
       (work / "partial.yaml").string()},
      work.path());
  EXPECT_EQ(intrinsics.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(intrinsics.Stderr().find("no intrinsics for camera cam02"), std::string::npos)
      << intrinsics.Stderr();
}

}  // namespace
}  // namespace silnet
