// Simulator benchmarks: one camera's mask and colour frame, and PNG encoding.
//   build/tests/bench/silnet_sim_bench

#include <benchmark/benchmark.h>

#include "shared/io/png_writer.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"

namespace silnet::sim {
namespace {

struct World {
  std::vector<CameraModel> cameras = MakeCameraNetwork(CameraNetworkOptions{});
  Scene scene{[] {
    SceneOptions o;
    o.time_begin = -1;
    o.time_end = 30;
    return o;
  }()};
  CameraRenderer renderer{cameras[0], scene, RenderSettings{}, 0};
};

World& TheWorld() {
  static World world;
  return world;
}

void BM_RenderMask640x480(benchmark::State& state) {
  World& w = TheWorld();
  cv::Mat mask;
  double t = 0.0;
  for (auto _ : state) {
    w.renderer.Render(t, 0, &mask, nullptr);
    t += 1.0 / 30.0;
  }
}
BENCHMARK(BM_RenderMask640x480)->Unit(benchmark::kMillisecond);

void BM_RenderMaskAndColour640x480(benchmark::State& state) {
  World& w = TheWorld();
  cv::Mat mask, colour;
  double t = 0.0;
  for (auto _ : state) {
    w.renderer.Render(t, 1, &mask, &colour);
    t += 1.0 / 30.0;
  }
}
BENCHMARK(BM_RenderMaskAndColour640x480)->Unit(benchmark::kMillisecond);

void BM_EncodePngColour640x480(benchmark::State& state) {
  World& w = TheWorld();
  cv::Mat mask, colour;
  w.renderer.Render(1.0, 1, &mask, &colour);
  for (auto _ : state)
    benchmark::DoNotOptimize(EncodePngFast(colour));
}
BENCHMARK(BM_EncodePngColour640x480)->Unit(benchmark::kMillisecond);

void BM_EncodePngMask640x480(benchmark::State& state) {
  World& w = TheWorld();
  cv::Mat mask;
  w.renderer.Render(1.0, 1, &mask, nullptr);
  for (auto _ : state)
    benchmark::DoNotOptimize(EncodePngFast(mask));
}
BENCHMARK(BM_EncodePngMask640x480)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace silnet::sim

BENCHMARK_MAIN();
