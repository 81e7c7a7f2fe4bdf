// Stills on command between real processes over loopback DDS (issue 19): eight silnet-node
// processes replay simulated cameras; `silnet-aggregator stills` asks each for the frame of
// one reference instant, three of them lose or corrupt chunks on the way, and a ninth camera
// of the calibration has no node. Every still that exists arrives whole (the lost and corrupt
// chunks fetched again), is the replayed frame the instant names and carries the node's
// silhouette of it; the missing camera is reported with its reason; the folder written loads
// as the stereo job's input.

#include <gtest/gtest.h>
#include <signal.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "aggregator/ingest/still_views.h"
#include "aggregator/stereo/stills_folder.h"
#include "shared/io/calibration_yaml.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

using std::chrono::seconds;

const std::filesystem::path kBin = SILNET_BINARY_DIR;
constexpr int kCameras = 8;
// Reference seconds of the still: well after the nodes' background models warmed up (7.5 s)
// and cleared what they learnt of the subject then.
constexpr double kInstant = 15.0;

std::string CameraName(int i) {
  char name[16];
  std::snprintf(name, sizeof(name), "cam%02d", i);
  return name;
}

std::string FrameFile(uint64_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06llu.png", static_cast<unsigned long long>(frame));
  return name;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  const double both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either > 0 ? both / either : 0.0;
}

TEST(StillsOnCommand, EveryNodeSendsTheStillOfTheInstantWholeAndAMissingNodeIsReported) {
  testing::TempDir work("silnet-stills");
  const std::filesystem::path data = work / "data";
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", data.string(), "--cameras", std::to_string(kCameras),
                             "--frames", "480", "--seed", "21"},
                            work.path());
  ASSERT_EQ(sim.Wait(seconds(600)), std::optional<int>(0)) << sim.Stderr();
  // The calibration in use: the true cameras plus one whose node never runs.
  std::vector<CameraModel> cameras = LoadCalibration(data / "ground_truth.yaml");
  CameraModel absent = cameras.back();
  absent.id = "cam99";
  cameras.push_back(absent);
  SaveCalibration(work / "calibration.yaml", cameras);

  // Faults on the first sending: cam01 loses a chunk, cam02 has one corrupted, cam03 both.
  const std::map<int, std::vector<std::string>> faults{
      {1, {"--test-drop-still-chunk", "2"}},
      {2, {"--test-corrupt-still-chunk", "1"}},
      {3, {"--test-drop-still-chunk", "0", "--test-corrupt-still-chunk", "3"}}};
  std::vector<std::unique_ptr<testing::ChildProcess>> nodes;
  for (int i = 0; i < kCameras; ++i) {
    // Lossless, so a busy machine slows the replay down instead of dropping the instant's
    // frame.
    std::vector<std::string> args{
        "--camera-id", CameraName(i), "--source", "sim:" + (data / CameraName(i)).string(),
        "--lossless",  "--linger",    "120",      "--still-chunk-kb",
        "32"};
    if (faults.count(i)) args.insert(args.end(), faults.at(i).begin(), faults.at(i).end());
    nodes.push_back(
        std::make_unique<testing::ChildProcess>(kBin / "node/silnet-node", args, work.path()));
  }
  const std::filesystem::path out = work / "stills";
  testing::ChildProcess aggregator(
      kBin / "aggregator/silnet-aggregator",
      {"stills", out.string(), "--calib", (work / "calibration.yaml").string(), "--at",
       std::to_string(kInstant), "--timeout", "60", "--discovery", "12"},
      work.path());
  ASSERT_EQ(aggregator.Wait(seconds(120)), std::optional<int>(0))
      << aggregator.Stdout() << aggregator.Stderr();
  EXPECT_NE(aggregator.Stdout().find("8 of 9 cameras answered"), std::string::npos)
      << aggregator.Stdout();
  EXPECT_NE(aggregator.Stdout().find("cam99: no still (no node of this camera was found)"),
            std::string::npos)
      << aggregator.Stdout();

  cv::FileStorage summary((out / "stills.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(summary.isOpened());
  EXPECT_EQ(static_cast<int>(summary["complete"]), kCameras);
  const cv::FileNode entries = summary["cameras"];
  ASSERT_EQ(static_cast<int>(entries.size()), kCameras + 1);
  for (int i = 0; i < kCameras; ++i) {
    const cv::FileNode entry = entries[i];
    const std::string id = CameraName(i);
    ASSERT_EQ(static_cast<std::string>(entry["id"]), id);
    ASSERT_EQ(static_cast<int>(entry["complete"]), 1) << id;
    // The frame the instant names on this camera's clock, and exactly that frame's image.
    const uint64_t frame = std::stoull(static_cast<std::string>(entry["frame_index"]));
    EXPECT_EQ(frame, aggregator::FirstFrameAtOrAfter(cameras[static_cast<size_t>(i)], kInstant))
        << id;
    const cv::Mat photo = cv::imread((out / id / "stills/000000.png").string(), cv::IMREAD_COLOR);
    const cv::Mat replayed =
        cv::imread((data / id / "frames" / FrameFile(frame)).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(photo.empty()) << id;
    ASSERT_EQ(photo.size(), replayed.size()) << id;
    EXPECT_EQ(cv::norm(photo, replayed, cv::NORM_INF), 0.0) << id;
    // The node's silhouette of it agrees with the exact one.
    const cv::Mat mask = cv::imread((out / id / "masks/000000.png").string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat exact =
        cv::imread((data / id / "masks" / FrameFile(frame)).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(mask.empty()) << id;
    EXPECT_GT(Iou(mask > 128, exact > 128), 0.8) << id;
    // Lost and corrupt chunks were recognised and fetched again.
    const int corrupt = static_cast<int>(entry["chunks_corrupt"]);
    const int resends = static_cast<int>(entry["resend_requests"]);
    EXPECT_EQ(static_cast<int>(entry["frame_flags"]) & silnet_wire_FRAME_WARMUP, 0) << id;
    if (i == 2 || i == 3) {
      EXPECT_GE(corrupt, 1) << id;
    }
    if (faults.count(i)) {
      EXPECT_GE(resends, 1) << id;
    } else {
      EXPECT_EQ(corrupt, 0) << id;
    }
  }
  const cv::FileNode missing = entries[kCameras];
  EXPECT_EQ(static_cast<std::string>(missing["id"]), "cam99");
  EXPECT_EQ(static_cast<int>(missing["complete"]), 0);
  EXPECT_EQ(static_cast<std::string>(missing["reason"]), "no node of this camera was found");

  // The folder is the stereo job's input, with the calibration of the cameras that answered.
  const aggregator::StereoViews views = aggregator::LoadStillsFolder(out, out / "calibration.yaml");
  EXPECT_EQ(views.views.size(), static_cast<size_t>(kCameras));
  EXPECT_TRUE(views.warnings.empty());

  // Stills of the empty scene: every node keeps its own (for the stills of a still stream of
  // its own, which these replayed feeds do not have) and sends it; it is written as the
  // stills folder's background.
  const std::filesystem::path empty = work / "empty";
  testing::ChildProcess backgrounds(
      kBin / "aggregator/silnet-aggregator",
      {"stills", empty.string(), "--calib", (work / "calibration.yaml").string(), "--background",
       "--timeout", "60", "--discovery", "12"},
      work.path());
  ASSERT_EQ(backgrounds.Wait(seconds(120)), std::optional<int>(0))
      << backgrounds.Stdout() << backgrounds.Stderr();
  EXPECT_NE(backgrounds.Stdout().find("8 of 9 cameras sent the empty scene"), std::string::npos)
      << backgrounds.Stdout();
  for (int i = 0; i < kCameras; ++i) {
    const cv::Mat background =
        cv::imread((empty / CameraName(i) / "background.png").string(), cv::IMREAD_COLOR);
    const cv::Mat frame =
        cv::imread((data / CameraName(i) / "frames" / FrameFile(0)).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(background.empty()) << CameraName(i);
    EXPECT_EQ(background.size(), frame.size()) << CameraName(i);
  }
  for (auto& node : nodes) {
    EXPECT_NE(node->Stderr().find("kept as the empty scene"), std::string::npos);
    node->Signal(SIGTERM);
    EXPECT_EQ(node->Wait(seconds(60)), std::optional<int>(0)) << node->Stderr();
  }
}

// The user's story on the simulator: the nodes' still streams show a statue at 1.5 times the
// video resolution; `stills --stereo` collects every photo with the node's silhouette of it
// (segmented against the empty room), builds the model with the calibration in use (here the
// true cameras moved into another frame and scale, as a self-calibration would give them) and
// scores it against the statue's true surface after aligning that calibration to the truth.
TEST(StillsOnCommand, TheModelFromTheNodesStillsIsScoredAgainstTheStatuesTrueSurface) {
  testing::TempDir work("silnet-stills-statue");
  const std::filesystem::path data = work / "data";
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", data.string(), "--cameras", std::to_string(kCameras),
                             "--frames", "240", "--seed", "22", "--frames-only"},
                            work.path());
  ASSERT_EQ(sim.Wait(seconds(600)), std::optional<int>(0)) << sim.Stderr();
  testing::ChildProcess statue(kBin / "sim/silnet-sim",
                               {"stills", "-o", (data / "statue").string(), "--cameras-from",
                                data.string(), "--scale", "1.5", "--backgrounds", "--seed", "22"},
                               work.path());
  ASSERT_EQ(statue.Wait(seconds(300)), std::optional<int>(0)) << statue.Stderr();
  // The calibration in use: the truth in another frame (rotated, shifted, half the scale).
  std::vector<CameraModel> cameras = LoadCalibration(data / "ground_truth.yaml");
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.2, 1).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(1.5, -2.0, 0.3);
  for (CameraModel& c : cameras) {
    // X' = 0.5 turn X + shift: x_cam = R turn^T (X' - shift) / 0.5, scaled by 0.5.
    c.t = 0.5 * c.t - c.R * turn.transpose() * shift;
    c.R = c.R * turn.transpose();
  }
  SaveCalibration(work / "calibration.yaml", cameras);

  std::vector<std::unique_ptr<testing::ChildProcess>> nodes;
  for (int i = 0; i < kCameras; ++i) {
    nodes.push_back(std::make_unique<testing::ChildProcess>(
        kBin / "node/silnet-node",
        std::vector<std::string>{"--camera-id", CameraName(i), "--source",
                                 "sim:" + (data / CameraName(i)).string(), "--lossless", "--linger",
                                 "60"},
        work.path()));
  }
  const std::filesystem::path out = work / "stills";
  testing::ChildProcess aggregator(
      kBin / "aggregator/silnet-aggregator",
      {"stills", out.string(), "--calib", (work / "calibration.yaml").string(), "--timeout", "60",
       "--discovery", "20", "--stereo", "--truth", (data / "statue").string()},
      work.path());
  ASSERT_EQ(aggregator.Wait(seconds(600)), std::optional<int>(0))
      << aggregator.Stdout() << aggregator.Stderr();
  const std::string said = aggregator.Stdout();
  EXPECT_NE(said.find("8 of 8 cameras answered"), std::string::npos) << said;
  EXPECT_NE(said.find("rotation 0.000 deg median"), std::string::npos) << said;
  for (auto& node : nodes)
    node->Kill(SIGTERM);

  cv::FileStorage summary((out / "stereo/stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(summary.isOpened());
  EXPECT_EQ(static_cast<int>(summary["views"]), kCameras);
  const cv::FileNode model = summary["model"], hull = summary["hull"];
  EXPECT_EQ(static_cast<int>(model["closed_manifold"]), 1);
  const double accuracy = model["evaluation"]["accuracy_footprints"];
  const double within2 = model["evaluation"]["completeness"][1]["fraction"];
  const double hull_accuracy = hull["evaluation"]["accuracy_footprints"];
  const double hull_within2 = hull["evaluation"]["completeness"][1]["fraction"];
  std::printf(
      "statue from the nodes' stills: accuracy %.2f fp (hull %.2f), %.1f %% within 2 fp "
      "(hull %.1f %%)\n",
      accuracy, hull_accuracy, 100.0 * within2, 100.0 * hull_within2);
  // Measured 5.99 fp and 83.2 % (hull 9.49 fp, 76.9 %); 5.28 fp and 87.6 % with the camouflage
  // test, the weak evidence and the registration at the statue. With the exact silhouettes the same
  // cameras give 1.44 fp and 98.0 %: the gap is the single-image segmentation of a grey statue
  // in front of a grey wall (IoU 0.93-0.99), not the transport or the calibration's alignment.
  EXPECT_LT(accuracy, 8.0);
  EXPECT_LT(accuracy, 0.8 * hull_accuracy);
  EXPECT_GT(within2, 0.8);
  EXPECT_GT(within2, hull_within2);
}

}  // namespace
}  // namespace silnet
