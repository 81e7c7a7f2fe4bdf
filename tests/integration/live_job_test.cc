// The main job with real processes: silnet-sim starts eight silnet-node processes replaying
// a simulated capture over loopback DDS, and silnet-aggregator live ingests, calibrates once
// it has enough frames, publishes the calibration, builds hulls of the frames that follow and
// writes the report; then it asks the nodes for stills of the statue standing in the room
// (every still losing a chunk and having another corrupted on the way) and builds the stereo
// model. The calibration must meet the network accuracy targets (DESIGN.md), no frame may be
// lost, the hulls must be closed and reproject onto the silhouettes, a reader must receive
// the published calibration, no camera may be reported moved, every still must arrive whole
// and the model must be closed and nearer the statue's true surface than its hull. As a service
// (--serve) it notices a camera knocked out of place mid-run, re-estimates it and publishes
// the corrected calibration, shows its state through `silnet-aggregator status`,
// recalibrates on the newest frames when `silnet-aggregator recalibrate` asks, and takes stills
// when `silnet-aggregator stills` asks (before the first calibration too: they wait for it).

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <fstream>
#include <functional>
#include <opencv2/core/persistence.hpp>
#include <set>
#include <thread>

#include "shared/dds/topics.h"
#include "tests/support/child_process.h"
#include "tests/support/eventually.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::seconds;
using testing::Eventually;

const std::filesystem::path kBin = SILNET_BINARY_DIR;

// An 8-camera ring of `frames` exact masks (seed 1) in work/dataset, with `extra` arguments
// for `silnet-sim generate`; empty path on failure.
std::filesystem::path GenerateMaskCapture(const testing::TempDir& work, int frames,
                                          const std::vector<std::string>& extra = {}) {
  const std::filesystem::path dataset = work / "dataset";
  std::vector<std::string> args = {"generate", "-o",          dataset.string(),       "--cameras",
                                   "8",        "--frames",    std::to_string(frames), "--seed",
                                   "1",        "--masks-only"};
  args.insert(args.end(), extra.begin(), extra.end());
  testing::ChildProcess sim(kBin / "sim/silnet-sim", args, work.path());
  const std::optional<int> status = sim.Wait(seconds(300));
  EXPECT_EQ(status, std::optional<int>(0)) << sim.Stderr();
  return status == std::optional<int>(0) ? dataset : std::filesystem::path();
}

// `silnet-sim run-nodes`: a node per camera replaying its masks at twice the frame rate,
// lossless (capture waits for segmentation): on a busy machine a node would otherwise drop
// frames, and the calibration's figures would depend on the machine's load.
testing::ChildProcess StartMaskNodes(const testing::TempDir& work,
                                     const std::filesystem::path& dataset, int linger_s,
                                     const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"run-nodes",
                                dataset.string(),
                                "--masks",
                                "--speed",
                                "2",
                                "--linger",
                                std::to_string(linger_s),
                                "--logs",
                                (work / "node-logs").string(),
                                "--node-arg=--lossless"};
  args.insert(args.end(), extra.begin(), extra.end());
  return testing::ChildProcess(kBin / "sim/silnet-sim", args, work.path());
}

TEST(LiveJob, SimulatedNodesToCalibratedNetworkHullsStillsModelAndReport) {
  testing::TempDir work;
  const std::filesystem::path dataset = GenerateMaskCapture(work, 480);
  ASSERT_FALSE(dataset.empty());
  // Once the walk is over a statue stands in the room: the nodes' still streams show it.
  testing::ChildProcess statue(kBin / "sim/silnet-sim",
                               {"stills", "-o", (dataset / "statue").string(), "--cameras-from",
                                dataset.string(), "--backgrounds", "--seed", "1"},
                               work.path());
  ASSERT_EQ(statue.Wait(seconds(300)), std::optional<int>(0)) << statue.Stderr();
  // A reader of the latched Calibration topic, as a node or tool would have.
  dds::Participant participant;
  dds::Topic<silnet_wire_Calibration> topic(participant);
  dds::Reader<silnet_wire_Calibration> calibrations(topic);
  const std::filesystem::path out = work / "live";
  // The streams end (480 frames) long before the calibration of the first 400 does: the
  // silence then must not count as the streams going quiet while the job waits for hull
  // frames it already holds (--give-up-after shorter than any calibration).
  testing::ChildProcess live(kBin / "aggregator/silnet-aggregator",
                             {"live",
                              "-o",
                              out.string(),
                              "--cameras",
                              "8",
                              "--calibrate-after",
                              "400",
                              "--hull-frames",
                              "8",
                              "--hulls-continuous",
                              "--hull-gap",
                              "20",
                              "--ground-truth",
                              (dataset / "ground_truth.yaml").string(),
                              "--idle-exit",
                              "3",
                              "--give-up-after",
                              "15",
                              "--stills",
                              "--stills-truth",
                              (dataset / "statue").string()},
                             work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // The nodes stay for the still requests; every still loses one chunk and has another
  // corrupted on its first sending.
  testing::ChildProcess nodes = StartMaskNodes(
      work, dataset, 600,
      {"--node-arg=--still-chunk-kb", "--node-arg=64", "--node-arg=--test-drop-still-chunk",
       "--node-arg=2", "--node-arg=--test-corrupt-still-chunk", "--node-arg=0"});
  ASSERT_EQ(live.Wait(seconds(600)), std::optional<int>(0)) << live.Stdout() << live.Stderr();
  nodes.Signal(SIGTERM);
  ASSERT_EQ(nodes.Wait(seconds(60)), std::optional<int>(0)) << nodes.Stderr();
  std::printf("%s", live.Stdout().c_str());
  std::set<std::string> calibrated;
  calibrations.Take([&](const silnet_wire_Calibration& c, const dds_sample_info_t& info) {
    if (info.valid_data) calibrated.insert(dds::ReadBoundedString(c.camera_id));
  });
  EXPECT_EQ(calibrated.size(), 8u);

  cv::FileStorage summary((out / "live_summary.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(summary.isOpened());
  EXPECT_EQ(static_cast<std::string>(summary["failure"]), "");
  EXPECT_EQ(static_cast<double>(summary["frames_held"]), 8 * 480.0);
  EXPECT_EQ(static_cast<double>(summary["frames_missing"]), 0.0);
  EXPECT_EQ(static_cast<int>(summary["published"]), 1);
  EXPECT_EQ(static_cast<int>(summary["cameras_calibrated"]), 8);
  EXPECT_EQ(summary["camera_moves"].size(), 0u) << "a camera reported moved on a steady rig";
  // DESIGN.md accuracy targets: reprojection <= 0.3 px, focal <= 1 %, rotation <= 0.2 deg,
  // offsets after network sync <= 0.05 frame.
  EXPECT_LE(static_cast<double>(summary["reprojection_rms_px"]), 0.3);
  const cv::FileNode truth = summary["ground_truth"];
  ASSERT_FALSE(truth.empty());
  EXPECT_LE(static_cast<double>(truth["median_focal_rel"]), 0.01);
  EXPECT_LE(static_cast<double>(truth["median_rotation_deg"]), 0.2);
  EXPECT_LE(static_cast<double>(truth["max_offset_frames"]), 0.05);
  const cv::FileNode hulls = summary["hulls"];
  ASSERT_FALSE(hulls.empty());
  // Continuous hulls: batch after batch of 8 from frame 420 until the streams ended (the
  // newest reference frames need frames up to 15 frames later from the other cameras).
  EXPECT_EQ(static_cast<int>(hulls["first_frame"]), 420);
  const int built = static_cast<int>(hulls["built"]);
  EXPECT_GE(built, 40);
  EXPECT_EQ(static_cast<int>(hulls["frames"]), built);
  // Every batch read the contours this run received from memory, none the session logs.
  EXPECT_NE(live.Stderr().find("(contours from memory)"), std::string::npos) << live.Stderr();
  EXPECT_EQ(live.Stderr().find("(contours from the session logs)"), std::string::npos);
  for (int frame = 420; frame < 420 + built; ++frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06d.ply", frame);
    EXPECT_TRUE(std::filesystem::exists(out / "hulls" / name)) << name;
  }
  cv::FileStorage index((out / "hulls/hulls.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(index.isOpened());
  ASSERT_EQ(static_cast<int>(index["frames"].size()), built);
  std::string missed_per_frame;
  for (int k = 0; k < built; ++k) {
    const cv::FileNode frame = index["frames"][k];
    EXPECT_EQ(static_cast<int>(frame["frame"]), 420 + k);
    EXPECT_EQ(static_cast<int>(frame["closed_manifold"]), 1);
    double missed = 0.0;
    for (const cv::FileNode& view : frame["views"])
      missed += static_cast<double>(view["missed_fraction"]) / 8.0;
    missed_per_frame += std::to_string(420 + k) + ": " + std::to_string(missed) + "\n";
  }
  // Exact hulls with the estimated calibration (rotation ~0.13 deg, a pixel or two at the
  // subject): the cones of slightly misplaced cameras intersect a little short of every
  // silhouette, so frames with the limbs spread miss up to ~4 % of its pixels; the mean over
  // a run was 1.6 % (1.8 % in the demo), while they cover only 2-3 % outside it. (Carved
  // voxels missed 1.3 % but covered ~6 % outside; with the true cameras the exact hull of the
  // walker misses 0.6 %: tests/aggregator/hulls.)
  EXPECT_LE(static_cast<double>(hulls["mean_missed"]), 0.03) << missed_per_frame;
  EXPECT_LE(static_cast<double>(hulls["mean_spurious"]), 0.04);
  EXPECT_TRUE(std::filesystem::exists(out / "report.html"));
  // The hulls to step through in 3D (drawn in Chromium by the report tests).
  EXPECT_TRUE(std::filesystem::exists(out / "viewer/three.min.js"));
  const int step = (built + 39) / 40;  // at most 40 frames, evenly spaced, go into the view
  for (int k = 0; k < built; k += step)
    EXPECT_TRUE(std::filesystem::exists(out / fmt::format("viewer/hull_{}.js", 420 + k))) << k;
  EXPECT_TRUE(std::filesystem::exists(out / "calibration/report/report.html"));
  EXPECT_TRUE(std::filesystem::exists(out / "calibration/calibration.yaml"));
  EXPECT_NE(live.Stdout().find("8 of 8 cameras"), std::string::npos) << live.Stdout();

  // Stills: every camera's whole, the lost and corrupt chunks fetched again; the model built
  // with the live calibration is closed and nearer the statue's true surface than its hull.
  const cv::FileNode stills = summary["stills"];
  ASSERT_FALSE(stills.empty());
  EXPECT_EQ(static_cast<int>(stills["complete"]), 8);
  EXPECT_EQ(static_cast<int>(stills["usable"]), 8);
  cv::FileStorage collected((out / "stills/stills.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(collected.isOpened());
  for (const cv::FileNode& camera : collected["cameras"]) {
    const std::string id = camera["id"];
    EXPECT_EQ(static_cast<int>(camera["complete"]), 1) << id;
    EXPECT_GE(static_cast<int>(camera["chunks_corrupt"]), 1) << id;
    EXPECT_GE(static_cast<int>(camera["resend_requests"]), 1) << id;
  }
  cv::FileStorage stereo((out / "stills/stereo/stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(stereo.isOpened());
  EXPECT_EQ(static_cast<int>(stereo["model"]["closed_manifold"]), 1);
  const double accuracy = stereo["model"]["evaluation"]["accuracy_footprints"];
  const double hull_accuracy = stereo["hull"]["evaluation"]["accuracy_footprints"];
  const double within_2fp = stereo["model"]["evaluation"]["completeness"][1]["fraction"];
  std::printf(
      "statue from the live calibration: accuracy %.2f fp (hull %.2f), %.1f %% within 2 fp\n",
      accuracy, hull_accuracy, 100 * within_2fp);
  EXPECT_LT(accuracy, hull_accuracy);
  // The stereo issue's targets: accuracy <= 1.5 fp, >= 97 % within 2 fp. Measured 1.04-1.09 fp
  // and 97.05-97.7 % in the runs kept, the live calibration differing run to run (registered
  // at the statue; outline pixels the statue covers less than half of dropped by the nodes,
  // weak silhouette evidence confirmed by the other views' silhouettes and weak evidence:
  // docs/PERFORMANCE.md).
  EXPECT_LE(accuracy, 1.5);
  EXPECT_GE(within_2fp, 0.97);
  EXPECT_NE(live.Stdout().find("stills       8 of 8 cameras"), std::string::npos) << live.Stdout();
  // The report tells the missed silhouette pixels no consistent model covers apart, as the
  // stereo job counted them.
  std::ifstream report(out / "report.html");
  const std::string page((std::istreambuf_iterator<char>(report)), {});
  const cv::FileNode model = stereo["model"];
  EXPECT_NE(page.find(fmt::format("inside missed {} ({} no model consistent with the other views",
                                  static_cast<int>(model["missed_inner_pixels"]),
                                  static_cast<int>(model["missed_uncoverable_pixels"]))),
            std::string::npos);
}

// The state of the live job's answer to the last stills request in `out` ("" if none yet).
std::string StillsAnswerState(const std::filesystem::path& out) {
  if (!std::filesystem::exists(out / "stills_answer.yaml")) return "";
  cv::FileStorage answer((out / "stills_answer.yaml").string(), cv::FileStorage::READ);
  return answer.isOpened() ? static_cast<std::string>(answer["state"]) : "";
}

// Frames the live job in `out` holds from all cameras, by its status file (0 if none yet).
double FramesHeld(const std::filesystem::path& out) {
  const std::filesystem::path path = out / "session/ingest_summary.yaml";
  if (!std::filesystem::exists(path)) return 0.0;
  cv::FileStorage status(path.string(), cv::FileStorage::READ);
  double held = 0.0;
  for (const cv::FileNode& camera : status["cameras"])
    held += static_cast<double>(camera["frames_held"]);
  return held;
}

TEST(LiveJob, AsAServiceItReestimatesAMovedCameraRecalibratesAndTakesStillsWhenAsked) {
  testing::TempDir work;
  // cam03 pans 2 degrees and shifts 5 cm sideways at frame 560.
  const std::filesystem::path dataset =
      GenerateMaskCapture(work, 1000, {"--move-camera", "cam03@560:2:0.05"});
  ASSERT_FALSE(dataset.empty());
  const std::filesystem::path out = work / "live";
  testing::ChildProcess live(
      kBin / "aggregator/silnet-aggregator",
      {"live", "-o", out.string(), "--serve", "--cameras", "8", "--calibrate-after", "400",
       "--hull-frames", "0", "--ground-truth", (dataset / "ground_truth.yaml").string()},
      work.path());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // Stills asked for before there is a calibration wait for it. The nodes stay for them.
  testing::ChildProcess early(kBin / "aggregator/silnet-aggregator",
                              {"stills", out.string(), "--no-stereo", "--no-wait"}, work.path());
  ASSERT_EQ(early.Wait(seconds(30)), std::optional<int>(0)) << early.Stderr();
  testing::ChildProcess nodes = StartMaskNodes(work, dataset, 600);
  ASSERT_TRUE(Eventually([&] { return StillsAnswerState(out) == "waiting"; }, seconds(60)));
  ASSERT_TRUE(Eventually(
      [&] { return live.Stderr().find("live: calibration published") != std::string::npos; },
      seconds(400)))
      << live.Stderr();
  ASSERT_TRUE(Eventually([&] { return StillsAnswerState(out) == "done"; }, seconds(120)))
      << live.Stderr();
  // Every frame has arrived before the operator asks for anything else.
  ASSERT_TRUE(Eventually([&] { return FramesHeld(out) == 8 * 1000.0; }, seconds(300)));
  ASSERT_TRUE(Eventually(
      [&] {
        return live.Stderr().find("live: calibration with cam03 re-estimated published") !=
               std::string::npos;
      },
      seconds(300)))
      << live.Stderr();
  EXPECT_NE(live.Stderr().find("CAMERA MOVED: cam03"), std::string::npos);
  // The operator's view and command: `status` shows every node and the moved camera,
  // `recalibrate` asks the running job for a new calibration.
  testing::ChildProcess status(kBin / "aggregator/silnet-aggregator", {"status", out.string()},
                               work.path());
  ASSERT_EQ(status.Wait(seconds(30)), std::optional<int>(0)) << status.Stderr();
  EXPECT_NE(status.Stdout().find("live job running"), std::string::npos) << status.Stdout();
  EXPECT_NE(status.Stdout().find("cam07"), std::string::npos) << status.Stdout();
  EXPECT_NE(status.Stdout().find("cam03 moved"), std::string::npos) << status.Stdout();
  testing::ChildProcess recalibrate(kBin / "aggregator/silnet-aggregator",
                                    {"recalibrate", out.string()}, work.path());
  ASSERT_EQ(recalibrate.Wait(seconds(30)), std::optional<int>(0)) << recalibrate.Stderr();
  ASSERT_TRUE(Eventually(
      [&] { return live.Stderr().find("live: new calibration published") != std::string::npos; },
      seconds(400)))
      << live.Stderr();
  EXPECT_NE(live.Stderr().find("recalibrating on frames 600..999"), std::string::npos);
  // `stills` asks the running job for stills with the calibration in use and follows its
  // answer; the job rewrites its report with them while it goes on.
  testing::ChildProcess empty(kBin / "aggregator/silnet-aggregator",
                              {"stills", out.string(), "--background"}, work.path());
  ASSERT_EQ(empty.Wait(seconds(180)), std::optional<int>(0)) << empty.Stdout() << live.Stderr();
  EXPECT_NE(empty.Stdout().find("empty scene  8 of 8 cameras"), std::string::npos)
      << empty.Stdout();
  for (int c = 0; c < 8; ++c)
    EXPECT_TRUE(
        std::filesystem::exists(out / fmt::format("backgrounds/cam{:02d}/background.png", c)));
  std::filesystem::remove(out / "report.html");
  testing::ChildProcess stills(kBin / "aggregator/silnet-aggregator",
                               {"stills", out.string(), "--no-stereo"}, work.path());
  ASSERT_EQ(stills.Wait(seconds(180)), std::optional<int>(0)) << stills.Stdout() << live.Stderr();
  // The job answers "running" first, but without stereo the stills may be done before the
  // command's next look at the answer: only the final answer is sure to be seen.
  EXPECT_TRUE(
      Eventually([&] { return live.Stderr().find("live: stills asked for") != std::string::npos; },
                 seconds(30)));
  EXPECT_NE(stills.Stdout().find("stills: done"), std::string::npos) << stills.Stdout();
  EXPECT_NE(stills.Stdout().find("8 of 8 cameras, 8 usable"), std::string::npos) << stills.Stdout();
  cv::FileStorage collected((out / "stills/stills.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(collected.isOpened());
  EXPECT_EQ(collected["cameras"].size(), 8u);
  for (const cv::FileNode& camera : collected["cameras"])
    EXPECT_EQ(static_cast<int>(camera["complete"]), 1) << static_cast<std::string>(camera["id"]);
  std::ifstream report(out / "report.html");
  const std::string page((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(page.find("Stills and stereo model"), std::string::npos);
  EXPECT_EQ(page.find("no stills asked for"), std::string::npos);
  live.Signal(SIGTERM);
  ASSERT_EQ(live.Wait(seconds(60)), std::optional<int>(0)) << live.Stderr();
  nodes.Signal(SIGTERM);
  ASSERT_EQ(nodes.Wait(seconds(60)), std::optional<int>(0)) << nodes.Stderr();
  std::printf("%s", live.Stdout().c_str());
  cv::FileStorage summary((out / "live_summary.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(summary.isOpened());
  EXPECT_EQ(static_cast<std::string>(summary["failure"]), "");
  // Only cam03 was reported moved, after its move, and its re-estimate (the other cameras
  // held as calibrated) matches its pose after the move.
  const cv::FileNode moves = summary["camera_moves"];
  ASSERT_EQ(moves.size(), 1u);
  EXPECT_EQ(static_cast<std::string>(moves[0]["id"]), "cam03");
  EXPECT_GT(static_cast<int>(moves[0]["detected_frame"]), 560);
  EXPECT_LE(static_cast<int>(moves[0]["detected_frame"]), 760);
  EXPECT_EQ(static_cast<int>(moves[0]["reestimated"]), 1);
  EXPECT_LE(static_cast<double>(moves[0]["rms_px"]), 0.5);
  EXPECT_GE(static_cast<double>(moves[0]["truth_rotation_deg"]), 0.0);
  EXPECT_LE(static_cast<double>(moves[0]["truth_rotation_deg"]), 0.3);
  EXPECT_TRUE(std::filesystem::exists(out / "camera_motion.yaml"));
  EXPECT_TRUE(std::filesystem::exists(
      out / ("camera-moved-cam03-" + std::to_string(static_cast<int>(moves[0]["detected_frame"]))) /
      "calibration.yaml"));
  // The recalibration on frames after the move meets the targets against the moved rig.
  EXPECT_EQ(static_cast<int>(summary["recalibrations"]), 1);
  EXPECT_EQ(static_cast<int>(summary["calibration_first_frame"]), 600);
  EXPECT_EQ(static_cast<int>(summary["cameras_calibrated"]), 8);
  const cv::FileNode truth = summary["ground_truth"];
  ASSERT_FALSE(truth.empty());
  EXPECT_LE(static_cast<double>(truth["median_focal_rel"]), 0.01);
  EXPECT_LE(static_cast<double>(truth["median_rotation_deg"]), 0.2);
  EXPECT_LE(static_cast<double>(truth["max_offset_frames"]), 0.05);
  EXPECT_TRUE(std::filesystem::exists(out / "recalibration-600/calibration.yaml"));
  EXPECT_EQ(static_cast<double>(summary["frames_missing"]), 0.0);
  EXPECT_FALSE(std::filesystem::exists(out / "live.pid"));
}

TEST(LiveJob, ServiceCommandsSayWhyWhenNoJobRunsThere) {
  testing::TempDir work;
  testing::ChildProcess recalibrate(kBin / "aggregator/silnet-aggregator",
                                    {"recalibrate", (work / "nothing").string()}, work.path());
  EXPECT_EQ(recalibrate.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(recalibrate.Stderr().find("no live job runs in"), std::string::npos)
      << recalibrate.Stderr();
  testing::ChildProcess stills(kBin / "aggregator/silnet-aggregator",
                               {"stills", (work / "nothing").string()}, work.path());
  EXPECT_EQ(stills.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(stills.Stderr().find("no live job runs in"), std::string::npos) << stills.Stderr();
  // A pid file left by a job that died.
  std::filesystem::create_directories(work / "dead/session");
  std::ofstream(work / "dead/live.pid") << 999999999 << "\n";
  std::ofstream(work / "dead/session/ingest_summary.yaml") << "%YAML:1.0\n---\ncameras: []\n";
  testing::ChildProcess again(kBin / "aggregator/silnet-aggregator",
                              {"recalibrate", (work / "dead").string()}, work.path());
  EXPECT_EQ(again.Wait(seconds(30)), std::optional<int>(2));
  testing::ChildProcess status(kBin / "aggregator/silnet-aggregator",
                               {"status", (work / "dead").string()}, work.path());
  EXPECT_EQ(status.Wait(seconds(30)), std::optional<int>(0)) << status.Stderr();
  EXPECT_NE(status.Stdout().find("no live job running"), std::string::npos) << status.Stdout();
  testing::ChildProcess nothing(kBin / "aggregator/silnet-aggregator",
                                {"status", (work / "nothing").string()}, work.path());
  EXPECT_EQ(nothing.Wait(seconds(30)), std::optional<int>(2));
  EXPECT_NE(nothing.Stderr().find("holds no live job's status"), std::string::npos)
      << nothing.Stderr();
}

}  // namespace
}  // namespace silnet
