// A camera knocked out of place after calibration (issue: the whole system live, aggregator as
// a service): the epipolar residuals of its pairs jump and the monitor reports it, and only
// it; re-estimated from frames after the move with the rest of the network held, its pose
// matches the simulator's moved camera. Simulated 8-camera ring, exact masks through the
// node's encoder; the calibration is the ground truth (the live job test runs the same on a
// calibration it estimated itself).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "aggregator/calibration/camera_motion_monitor.h"
#include "aggregator/calibration/moved_camera_reestimation.h"
#include "shared/util/check.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

constexpr int kFrames = 600;
constexpr int kMoveFrame = 300;
constexpr size_t kMoved = 3;
constexpr uint64_t kWindow = 90;

const testing::SimCapture& Capture() {
  static const testing::SimCapture capture =
      testing::MakeRingWithKnockedCamera(kMoved, kMoveFrame, kFrames);
  return capture;
}

double RotationDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / std::numbers::pi;
}

std::vector<bool> AllPlaced() {
  return std::vector<bool>(Capture().cameras.size(), true);
}

TEST(CameraMotionMonitor, ReportsOnlyTheCameraThatMovedAndOnlyAfterItMoved) {
  const testing::SimCapture& capture = Capture();
  CameraMotionMonitor monitor(capture.cameras, AllPlaced());
  monitor.SetBaseline(testing::SliceSequences(capture.sequences, 0, 150));
  ASSERT_TRUE(monitor.HasBaseline());
  bool reported = false;
  for (uint64_t first = 150; first + kWindow <= kFrames; first += kWindow) {
    const auto verdicts = monitor.Check(testing::SliceSequences(capture.sequences, first, kWindow));
    ASSERT_EQ(verdicts.size(), capture.cameras.size());
    const bool after_move = first >= static_cast<uint64_t>(kMoveFrame);
    for (const CameraMotionVerdict& v : verdicts) {
      SCOPED_TRACE(::testing::Message()
                   << "window " << first << " camera " << v.camera_id << " residual "
                   << v.residual_px << " px, baseline " << v.baseline_px << " px, "
                   << v.pairs_jumped << "/" << v.pairs_measured << " pairs jumped");
      EXPECT_GE(v.pairs_measured, 5u);
      if (v.camera != kMoved || first + kWindow <= static_cast<uint64_t>(kMoveFrame)) {
        EXPECT_FALSE(v.suspect);
        EXPECT_LT(v.residual_px, 1.0);
      } else if (after_move) {
        EXPECT_TRUE(v.suspect);
        EXPECT_GT(v.residual_px, 3.0 * v.baseline_px);
        reported = reported || v.moved;
      }
    }
  }
  EXPECT_TRUE(reported);
}

TEST(MovedCameraReestimation, RecoversThePoseAfterTheMoveWithTheOthersHeld) {
  const testing::SimCapture& capture = Capture();
  const auto after = testing::SliceSequences(capture.sequences, kMoveFrame, kFrames - kMoveFrame);
  const MovedCameraEstimate estimate =
      ReestimateMovedCamera(capture.cameras, AllPlaced(), kMoved, after, MovedCameraOptions{});
  ASSERT_TRUE(estimate.ok) << estimate.reason;
  EXPECT_GE(estimate.partners.size(), 4u);
  const CameraModel& truth = capture.cameras_at_end[kMoved];
  const double rotation = RotationDeg(truth.R, estimate.camera.R);
  const double centre_m = (truth.Center() - estimate.camera.Center()).norm();
  std::cout << "re-estimated " << truth.id << ": rotation error " << rotation << " deg, centre "
            << centre_m * 1000 << " mm, rms " << estimate.rms_px << " px over "
            << estimate.observations << " observations, " << estimate.seconds << " s\n";
  EXPECT_LT(rotation, 0.1);
  EXPECT_LT(centre_m, 0.02);
  EXPECT_LT(estimate.rms_px, 0.5);
  EXPECT_EQ(estimate.camera.K, truth.K);

  // Back in the monitor, the camera's pairs agree with the silhouettes again.
  CameraMotionMonitor monitor(capture.cameras, AllPlaced());
  monitor.SetBaseline(testing::SliceSequences(capture.sequences, 0, 150));
  monitor.ReplaceCamera(kMoved, estimate.camera,
                        testing::SliceSequences(capture.sequences, kMoveFrame, 150));
  for (const CameraMotionVerdict& v :
       monitor.Check(testing::SliceSequences(capture.sequences, kFrames - kWindow, kWindow))) {
    EXPECT_FALSE(v.suspect) << v.camera_id;
    EXPECT_LT(v.residual_px, 1.0) << v.camera_id;
  }
}

TEST(MovedCameraReestimation, SaysWhyWhenTheCameraHasNoFramesAfterTheMove) {
  const testing::SimCapture& capture = Capture();
  auto after = testing::SliceSequences(capture.sequences, kMoveFrame, 100);
  after.erase(after.begin() + static_cast<std::ptrdiff_t>(kMoved));
  const MovedCameraEstimate estimate =
      ReestimateMovedCamera(capture.cameras, AllPlaced(), kMoved, after, MovedCameraOptions{});
  EXPECT_FALSE(estimate.ok);
  EXPECT_NE(estimate.reason.find("no frames"), std::string::npos) << estimate.reason;
}

TEST(CameraMotionOptions, RejectsUnusableSettings) {
  CameraMotionOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.confirmations = 0;
  EXPECT_NE(options.Validate(), "");
  EXPECT_THROW(CameraMotionMonitor monitor(Capture().cameras, AllPlaced(), options), InputError);
}

}  // namespace
}  // namespace silnet::aggregator
