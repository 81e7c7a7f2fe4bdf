// Pairwise epipolar geometry (and offset) from silhouettes, one core:
//   build/tests/bench/silnet_pairwise_bench
// BM_SynchronisedPair1000: a synchronised 1000-frame pair (8-camera ring, cameras 0 and 2).
// BM_UnsynchronisedPair1000Search250: the same pair 120 frames apart, searched over +-250.

#include <benchmark/benchmark.h>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

const testing::SimCapture& Capture(bool synchronised) {
  static const auto make = [](bool sync) {
    sim::CameraNetworkOptions network;
    network.cameras = 8;
    network.max_offset = 0.0;
    network.seed = 4;
    sim::SceneOptions scene;
    scene.seed = 4;
    return testing::MakeSimCapture(network, scene, sync ? 1000 : 1240);
  };
  static const testing::SimCapture sync = make(true);
  static const testing::SimCapture unsync = make(false);
  return synchronised ? sync : unsync;
}

void BM_SynchronisedPair1000(benchmark::State& state) {
  const auto& capture = Capture(true);
  PairwiseOptions options;
  options.synchronized = true;
  uint64_t seed = 1;
  for (auto _ : state) {
    options.seed = seed++;
    const PairwiseResult r = EstimatePair(capture.sequences[0], capture.sequences[2], options);
    if (r.status != PairStatus::kOk) state.SkipWithError(r.reason.c_str());
    state.counters["inliers"] = static_cast<double>(r.inliers);
  }
}
BENCHMARK(BM_SynchronisedPair1000)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_UnsynchronisedPair1000Search250(benchmark::State& state) {
  const auto& capture = Capture(false);
  // Camera j's frames start 120 frames later: frame k of i is frame k - 120 of the cut j.
  SilhouetteSequence i = capture.sequences[0];
  SilhouetteSequence j = capture.sequences[2];
  i.frames.erase(i.frames.begin() + 1000, i.frames.end());
  j.frames.erase(j.frames.begin(), j.frames.begin() + 120);
  for (SilhouetteFrame& f : j.frames)
    f.index -= 120;
  j.frames.erase(j.frames.begin() + 1000, j.frames.end());
  i.Index();
  j.Index();
  PairwiseOptions options;
  options.offset_min = -250;
  options.offset_max = 250;
  uint64_t seed = 1;
  for (auto _ : state) {
    options.seed = seed++;
    const PairwiseResult r = EstimatePair(i, j, options);
    if (r.status != PairStatus::kOk || std::abs(r.offset + 120.0) > 0.2) {
      state.SkipWithError(("wrong or no solution: " + r.reason).c_str());
    }
    state.counters["offset"] = r.offset;
  }
}
BENCHMARK(BM_UnsynchronisedPair1000Search250)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace silnet::aggregator

BENCHMARK_MAIN();
