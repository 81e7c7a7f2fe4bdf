// Watching a calibrated network for moved cameras (aggregator/calibration), on a simulated
// 8-camera ring whose cam03 turns 2 degrees and shifts 6 cm at frame 300:
//   build/tests/bench/silnet_calibrate_bench --benchmark_filter=Motion
// BM_MotionCheck8x60: one check, every pair's epipolar residuals on a 60-frame window against
//   the calibration (the live job runs one per 60 frames, i.e. every 2 s at 30 fps); one core.
// BM_ReestimateMovedCamera240: the moved camera re-estimated from 240 frames after the move,
//   the others held (7 pairwise estimates in parallel, then its pose); both cores. Counter:
//   rotation error against its true pose after the move (degrees).

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <numbers>

#include "aggregator/calibration/camera_motion_monitor.h"
#include "aggregator/calibration/moved_camera_reestimation.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

constexpr size_t kMoved = 3;

const testing::SimCapture& MovedCapture() {
  static const testing::SimCapture capture = testing::MakeRingWithKnockedCamera(kMoved, 300, 600);
  return capture;
}

void BM_MotionCheck8x60(benchmark::State& state) {
  const auto& capture = MovedCapture();
  const std::vector<bool> placed(capture.cameras.size(), true);
  CameraMotionMonitor monitor(capture.cameras, placed);
  monitor.SetBaseline(testing::SliceSequences(capture.sequences, 0, 60));
  const auto window = testing::SliceSequences(capture.sequences, 400, 60);
  size_t suspects = 0;
  for (auto _ : state) {
    for (const CameraMotionVerdict& v : monitor.Check(window))
      suspects += v.suspect ? 1 : 0;
  }
  state.counters["suspects_per_check"] =
      static_cast<double>(suspects) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_MotionCheck8x60)->Unit(benchmark::kMillisecond);

void BM_ReestimateMovedCamera240(benchmark::State& state) {
  const auto& capture = MovedCapture();
  const std::vector<bool> placed(capture.cameras.size(), true);
  const auto after = testing::SliceSequences(capture.sequences, 360, 240);
  for (auto _ : state) {
    const MovedCameraEstimate e =
        ReestimateMovedCamera(capture.cameras, placed, kMoved, after, MovedCameraOptions{});
    if (!e.ok) {
      state.SkipWithError(e.reason.c_str());
      return;
    }
    const Eigen::Matrix3d d = capture.cameras_at_end[kMoved].R.transpose() * e.camera.R;
    state.counters["rotation_deg"] = Eigen::AngleAxisd(d).angle() * 180.0 / std::numbers::pi;
  }
}
BENCHMARK(BM_ReestimateMovedCamera240)->Unit(benchmark::kSecond)->Iterations(3);

}  // namespace
}  // namespace silnet::aggregator
