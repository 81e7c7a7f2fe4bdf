// silnet-sim's dataset folders: ground truth consistent with the rendered images, and the
// same seed giving the same bytes. The real executable is run in a child process.

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "shared/geometry/epipolar.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "sim/dataset_generator.h"
#include "sim/ground_truth.h"
#include "tests/sim/reference_raster.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet::sim {
namespace {

const std::filesystem::path kSim = std::filesystem::path(SILNET_BINARY_DIR) / "sim/silnet-sim";

void RunSim(const std::filesystem::path& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"generate", "-o",     out.string(), "--cameras", "4", "--frames",
                                   "12",       "--size", "320x240",    "--threads", "2"};
  args.insert(args.end(), extra.begin(), extra.end());
  silnet::testing::ChildProcess sim(kSim, args, out.parent_path());
  ASSERT_EQ(sim.Wait(std::chrono::seconds(120)), std::optional<int>(0)) << sim.Stderr();
}

std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The options silnet-sim uses for the runs above (to rebuild the scene in-process).
SimulationOptions OptionsFor(uint64_t seed) {
  SimulationOptions o;
  o.network.cameras = 4;
  o.network.width = 320;
  o.network.height = 240;
  o.network.seed = o.scene.seed = o.render.seed = seed;
  o.frames = 12;
  return o;
}

TEST(SimDataset, SameSeedSameBytesAndAnotherSeedDiffers) {
  silnet::testing::TempDir dir;
  RunSim(dir / "a", {"--seed", "7"});
  RunSim(dir / "b", {"--seed", "7"});
  RunSim(dir / "c", {"--seed", "8"});
  size_t compared = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir / "a")) {
    if (!entry.is_regular_file()) continue;
    const auto relative = std::filesystem::relative(entry.path(), dir / "a");
    ASSERT_EQ(ReadBytes(entry.path()), ReadBytes(dir / "b" / relative)) << relative;
    ++compared;
  }
  EXPECT_EQ(compared, 4u * 12u * 2u + 1u);
  EXPECT_NE(ReadBytes(dir / "a/cam00/masks/000005.png"),
            ReadBytes(dir / "c/cam00/masks/000005.png"));
  EXPECT_NE(ReadBytes(dir / "a/ground_truth.yaml"), ReadBytes(dir / "c/ground_truth.yaml"));
}

TEST(SimDataset, GroundTruthFundamentalMatricesHoldForProjectedPoints) {
  silnet::testing::TempDir dir;
  RunSim(dir / "d", {"--seed", "3", "--distortion", "0.1", "--masks-only"});
  const auto cameras = LoadCalibration(dir / "d/ground_truth.yaml");
  ASSERT_EQ(cameras.size(), 4u);
  cv::FileStorage fs((dir / "d/ground_truth.yaml").string(), cv::FileStorage::READ);
  const cv::FileNode pairs = fs["pairs"];
  ASSERT_EQ(pairs.size(), 6u);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (const cv::FileNode& pair : pairs) {
    const std::string i_id = pair["i"], j_id = pair["j"];
    const CameraModel& ci = cameras[static_cast<size_t>(std::stoi(i_id.substr(3)))];
    const CameraModel& cj = cameras[static_cast<size_t>(std::stoi(j_id.substr(3)))];
    cv::Mat f_mat;
    pair["F"] >> f_mat;
    Eigen::Matrix3d f;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        f(r, c) = f_mat.at<double>(r, c);
    // Pair offsets match the cameras' offsets.
    EXPECT_NEAR(static_cast<double>(pair["offset"]), ci.time_offset - cj.time_offset, 1e-9);
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d X(1.5 * u(rng), 1.5 * u(rng), 1.0 + u(rng));
      const auto pi = ci.Project(X), pj = cj.Project(X);
      ASSERT_TRUE(pi && pj);
      // F applies to undistorted pixels.
      worst = std::max(
          worst, SymmetricEpipolarDistance(f, ci.UndistortPixel(*pi), cj.UndistortPixel(*pj)));
    }
  }
  EXPECT_LT(worst, 0.01);
}

TEST(SimDataset, TimeOffsetsAreConsistentWithTheRenderedMotion) {
  silnet::testing::TempDir dir;
  RunSim(dir / "e", {"--seed", "4", "--masks-only", "--max-offset", "10"});
  const auto cameras = LoadCalibration(dir / "e/ground_truth.yaml");
  const SimulationOptions options = OptionsFor(4);
  const Scene scene(SceneForCameras(options, cameras));
  const DatasetLayout layout(dir / "e");
  for (const CameraModel& c : cameras) {
    for (int frame : {3, 8}) {
      const cv::Mat mask = cv::imread(layout.MaskPath(c.id, frame).string(), cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(mask.empty());
      // The mask matches the geometry at the camera's exposure time per the ground truth,
      // better than at any time a fraction of a frame away.
      double best_iou = -1.0, best_shift = 99.0;
      for (double shift = -1.0; shift <= 1.0; shift += 0.25) {
        const double iou = testing::MaskIoU(
            mask, testing::ReferenceMask(c, scene.PrimitivesAt(c.ExposureTime(frame + shift))));
        if (iou > best_iou) {
          best_iou = iou;
          best_shift = shift;
        }
      }
      EXPECT_EQ(best_shift, 0.0) << c.id << " frame " << frame;
      EXPECT_GE(best_iou, 0.99) << c.id << " frame " << frame;
    }
  }
}

TEST(SimDataset, StoredSubjectGeometryIsTheSceneAtReferenceFrames) {
  silnet::testing::TempDir dir;
  RunSim(dir / "g", {"--seed", "5", "--masks-only", "--subjects", "2"});
  const auto cameras = LoadCalibration(dir / "g/ground_truth.yaml");
  const Scene scene(SceneForCameras(
      [] {
        SimulationOptions o = OptionsFor(5);
        o.scene.count = 2;
        return o;
      }(),
      cameras));
  cv::FileStorage fs((dir / "g/ground_truth.yaml").string(), cv::FileStorage::READ);
  const int first = fs["subject_frames"]["first"];
  const int count = fs["subject_frames"]["count"];
  const auto [expected_first, expected_count] = ReferenceFrameRange(cameras, 12, 30.0);
  EXPECT_EQ(first, expected_first);
  EXPECT_EQ(count, expected_count);
  const cv::FileNode geometry = fs["subject_frames"]["geometry"];
  ASSERT_EQ(static_cast<int>(geometry.size()), count);
  int r = first;
  for (const cv::FileNode& node : geometry) {
    cv::Mat rows;
    node >> rows;
    const auto stored = DecodePrimitiveRows(rows);
    const auto truth = scene.PrimitivesAt(r / 30.0);
    ASSERT_EQ(stored.size(), truth.size());
    for (size_t i = 0; i < truth.size(); ++i) {
      EXPECT_LT((stored[i].center - truth[i].center).norm(), 1e-9);
      EXPECT_EQ(stored[i].subject, truth[i].subject);
    }
    ++r;
  }
  EXPECT_EQ(static_cast<int>(fs["part_names"].size()), 2 * 17);
}

TEST(SimDataset, AMovedCameraRendersFromItsNewPoseFromItsFrameOnAndTheGroundTruthSaysSo) {
  silnet::testing::TempDir dir;
  RunSim(dir / "steady", {"--seed", "7"});
  RunSim(dir / "moved", {"--seed", "7", "--move-camera", "cam01@6:3:0.1"});
  for (int frame = 0; frame < 12; ++frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "masks/%06d.png", frame);
    EXPECT_EQ(ReadBytes(dir / "steady/cam00" / name), ReadBytes(dir / "moved/cam00" / name));
    const bool same =
        ReadBytes(dir / "steady/cam01" / name) == ReadBytes(dir / "moved/cam01" / name);
    EXPECT_EQ(same, frame < 6) << name;
  }
  const auto truth = dir / "moved/ground_truth.yaml";
  const std::vector<CameraModel> before = LoadCamerasAtFrame(truth, 5);
  const std::vector<CameraModel> after = LoadCamerasAtFrame(truth, 6);
  ASSERT_EQ(before.size(), 4u);
  ASSERT_EQ(after.size(), 4u);
  EXPECT_EQ(LoadCalibration(truth)[1].R, before[1].R);
  CameraMove move;
  move.camera = 1;
  move.frame = 6;
  move.rotation_deg = 3.0;
  move.shift = Eigen::Vector3d(0.1, 0.0, 0.0);
  const CameraModel expected = MovedCamera(before[1], move);
  EXPECT_LT((after[1].R - expected.R).norm(), 1e-9);
  EXPECT_LT((after[1].Center() - expected.Center()).norm(), 1e-9);
  EXPECT_NEAR((after[1].Center() - before[1].Center()).norm(), 0.1, 1e-9);
  EXPECT_EQ(after[1].K, before[1].K);
  EXPECT_EQ(after[0].R, before[0].R);
}

TEST(SimDataset, BadOptionsFailWithAClearMessage) {
  silnet::testing::TempDir dir;
  silnet::testing::ChildProcess bad(
      kSim, {"generate", "-o", (dir / "x").string(), "--size", "64by48"}, dir.path());
  EXPECT_EQ(bad.Wait(std::chrono::seconds(30)), std::optional<int>(2));
  EXPECT_NE(bad.Stderr().find("image size"), std::string::npos) << bad.Stderr();
  std::filesystem::create_directories(dir / "full");
  std::ofstream(dir / "full/file") << "x";
  silnet::testing::ChildProcess not_empty(kSim, {"generate", "-o", (dir / "full").string()},
                                          dir.path());
  EXPECT_EQ(not_empty.Wait(std::chrono::seconds(30)), std::optional<int>(2));
  EXPECT_NE(not_empty.Stderr().find("not empty"), std::string::npos) << not_empty.Stderr();
  for (const auto& [move, message] :
       {std::pair{"cam09@5:1", "only 8 cameras"}, std::pair{"cam01@700:1", "within the capture"},
        std::pair{"cam01:5:1", "looks like"}}) {
    silnet::testing::ChildProcess moved(
        kSim, {"generate", "-o", (dir / "m").string(), "--move-camera", move}, dir.path());
    EXPECT_EQ(moved.Wait(std::chrono::seconds(30)), std::optional<int>(2)) << move;
    EXPECT_NE(moved.Stderr().find(message), std::string::npos) << moved.Stderr();
  }
}

}  // namespace
}  // namespace silnet::sim
