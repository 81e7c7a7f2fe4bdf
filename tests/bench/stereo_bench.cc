// Stereo benchmarks: photo-consistency (thesis 6.8.1) of the simulated statue seen by a ring
// of 16 cameras at 640x480 (`silnet-sim stills` defaults), all cores, default options; the
// visual hull it needs is computed once outside the timing.
//   build/tests/bench/silnet_stereo_bench --benchmark_repetitions=3

#include <benchmark/benchmark.h>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/photo_consistency.h"
#include "aggregator/stereo/stills_folder.h"
#include "sim/stills_generator.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

// The 16 views and their polyhedral hull.
struct Ring {
  StereoViews views;
  TriangleMesh hull;

  Ring() {
    silnet::testing::TempDir dir("silnet-stereo-bench");
    sim::StillsOptions options;
    options.overwrite = true;
    sim::GenerateStills(options, dir.path(), nullptr);
    views = LoadStillsFolder(dir.path(), dir.path() / "calibration.yaml");
    hull = ComputePolyhedralHull(views.Cameras(), views.Masks()).mesh;
  }
};

const Ring& TheRing() {
  static const Ring ring;
  return ring;
}

void BM_PhotoConsistency16Views(benchmark::State& state) {
  const Ring& ring = TheRing();
  PhotoConsistencyOptions options;
  options.pixel_step = static_cast<int>(state.range(0));
  PhotoConsistencyStats stats;
  for (auto _ : state) {
    const PhotoConsistencyResult result =
        ComputePhotoConsistency(ring.views.views, ring.hull, options);
    stats = result.stats;
    benchmark::DoNotOptimize(result.volume.votes.data());
  }
  state.counters["pixels"] = static_cast<double>(stats.reference_pixels);
  state.counters["matches"] = static_cast<double>(stats.matches);
  state.counters["votes"] = static_cast<double>(stats.votes_in_hull);
  state.counters["matching_s"] = stats.seconds_matching;
}
BENCHMARK(BM_PhotoConsistency16Views)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace silnet::aggregator

BENCHMARK_MAIN();
