// The whole calibrate job on 8 cameras x 600 frames (simulated ring, unsynchronised, offsets
// up to +-15 frames), both cores, as `silnet-aggregator calibrate` runs it without the report:
//   build/tests/bench/silnet_calibrate_bench
// BM_Calibrate8x600: pairs (all 28, in parallel) -> synchronisation -> calibration.
// BM_CalibrationStage8x600: the calibration stage alone, on the pairwise results.
// Counters: rotation error (degrees, median after a similarity alignment) and reprojection rms.

#include <benchmark/benchmark.h>

#include "aggregator/calibration/ground_truth_comparison.h"
#include "aggregator/calibration/network_calibration.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

const testing::SimCapture& Capture() {
  static const testing::SimCapture capture = [] {
    sim::CameraNetworkOptions network;
    network.cameras = 8;
    network.max_offset = 15.0;
    network.seed = 11;
    sim::SceneOptions scene;
    scene.seed = 11;
    return testing::MakeSimCapture(network, scene, 600);
  }();
  return capture;
}

void Report(benchmark::State& state, const NetworkCalibration& calibration) {
  if (calibration.PlacedCount() < 3) {
    state.SkipWithError("the network was not calibrated");
    return;
  }
  const CalibrationErrors e =
      CompareWithGroundTruth(calibration.cameras, calibration.PlacedMask(), Capture().cameras);
  state.counters["rotation_deg"] = e.median_rotation_deg;
  state.counters["rms_px"] = calibration.rms_px;
}

PairwiseJobOptions PairOptions() {
  PairwiseJobOptions options;
  options.pair.offset_min = -35;
  options.pair.offset_max = 35;
  return options;
}

void BM_Calibrate8x600(benchmark::State& state) {
  const auto& capture = Capture();
  for (auto _ : state) {
    const PairwiseJobResult pairs = EstimateAllPairs(capture.sequences, PairOptions());
    const NetworkCalibration calibration = CalibrateNetwork(
        testing::UncalibratedCopies(capture.cameras), pairs.pairs, &capture.sequences, {});
    Report(state, calibration);
  }
}
BENCHMARK(BM_Calibrate8x600)->Unit(benchmark::kSecond)->Iterations(3)->UseRealTime();

void BM_CalibrationStage8x600(benchmark::State& state) {
  const auto& capture = Capture();
  const PairwiseJobResult pairs = EstimateAllPairs(capture.sequences, PairOptions());
  for (auto _ : state) {
    const NetworkCalibration calibration = CalibrateNetwork(
        testing::UncalibratedCopies(capture.cameras), pairs.pairs, &capture.sequences, {});
    Report(state, calibration);
  }
}
BENCHMARK(BM_CalibrationStage8x600)->Unit(benchmark::kSecond)->Iterations(3)->UseRealTime();

}  // namespace
}  // namespace silnet::aggregator

BENCHMARK_MAIN();
