// Camera-node benchmarks on the simulator's default feed (640x480, noise, shadows, lighting
// changes), one core:
//   build/tests/bench/silnet_node_bench
// BM_HullTangentTableEncode: silhouette -> convex hull + tangent table + HullFrame encoding.
// BM_NodePipeline: colour frame -> segmentation -> hull, tangent table, contour -> encoded.
// BM_HullFrameBytes: HullFrame payload sizes over 8 cameras x 300 frames (counters).
// BM_EncodeStill/S: a commanded still at S times 640x480 (the frame upscaled): photo PNG and
//   silhouette PNG, on the node's still thread (counters: bytes).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "node/pipeline/frame_processor.h"
#include "node/publish/still_store.h"
#include "shared/silhouette/hull_codec.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"

namespace silnet {
namespace {

struct Feed {
  std::vector<CameraModel> cameras;
  std::unique_ptr<sim::Scene> scene;
};

Feed& TheFeed() {
  static Feed feed = [] {
    Feed f;
    sim::CameraNetworkOptions network;
    network.seed = 3;
    f.cameras = sim::MakeCameraNetwork(network);
    sim::SceneOptions scene;
    scene.seed = 3;
    scene.time_begin = -2;
    scene.time_end = 25;
    f.scene = std::make_unique<sim::Scene>(scene);
    return f;
  }();
  return feed;
}

// `count` consecutive frames (masks and colour) of camera 0 from frame `first`.
void RenderFrames(int first, int count, std::vector<cv::Mat>* masks,
                  std::vector<cv::Mat>* colours) {
  Feed& f = TheFeed();
  const sim::CameraRenderer renderer(f.cameras[0], *f.scene, sim::RenderSettings{}, 0);
  for (int k = first; k < first + count; ++k) {
    cv::Mat mask, colour;
    renderer.Render(f.cameras[0].ExposureTime(k), static_cast<uint64_t>(k), &mask,
                    colours != nullptr ? &colour : nullptr);
    masks->push_back(mask);
    if (colours != nullptr) colours->push_back(colour);
  }
}

void BM_HullTangentTableEncode(benchmark::State& state) {
  std::vector<cv::Mat> masks;
  RenderFrames(0, 60, &masks, nullptr);
  size_t i = 0;
  for (auto _ : state) {
    MaskSummary summary;
    HullPayload payload;
    payload.hull = ComputeSilhouetteHull(masks[i++ % masks.size()], &summary);
    payload.foreground_pixels = summary.foreground_pixels;
    benchmark::DoNotOptimize(EncodeHull(payload));
  }
}
BENCHMARK(BM_HullTangentTableEncode)->Unit(benchmark::kMicrosecond);

void BM_NodePipeline(benchmark::State& state) {
  std::vector<cv::Mat> masks, colours;
  RenderFrames(0, 300, &masks, &colours);
  cv::setNumThreads(1);
  node::FrameProcessorOptions options;
  options.camera_id = "cam00";
  node::FrameProcessor processor(options, 640, 480);
  // Train the background model on the first 240 frames, then time the last 60, cyclically.
  node::CapturedFrame frame;
  for (int k = 0; k < 240; ++k) {
    frame.image = colours[static_cast<size_t>(k)];
    frame.frame_index = static_cast<uint64_t>(k);
    processor.Process(frame);
  }
  uint64_t k = 240;
  for (auto _ : state) {
    frame.image = colours[240 + k % 60];
    frame.frame_index = k++;
    benchmark::DoNotOptimize(processor.Process(frame));
  }
}
BENCHMARK(BM_NodePipeline)->Unit(benchmark::kMillisecond);

void BM_EncodeStill(benchmark::State& state) {
  std::vector<cv::Mat> masks, colours;
  RenderFrames(100, 1, &masks, &colours);
  cv::setNumThreads(1);
  const double scale = static_cast<double>(state.range(0));
  cv::Mat photo, mask;
  cv::resize(colours[0], photo, cv::Size(), scale, scale, cv::INTER_LINEAR);
  cv::resize(masks[0], mask, cv::Size(), scale, scale, cv::INTER_NEAREST);
  size_t bytes = 0;
  for (auto _ : state) {
    const node::EncodedStill still = node::EncodeStill(1, 100, 0, 0, photo, mask);
    bytes = still.photo.size() + still.silhouette.size();
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodeStill)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_HullFrameBytes(benchmark::State& state) {
  Feed& f = TheFeed();
  std::vector<size_t> sizes;
  for (size_t c = 0; c < f.cameras.size(); ++c) {
    const sim::CameraRenderer renderer(f.cameras[c], *f.scene, sim::RenderSettings{},
                                       static_cast<int>(c));
    for (int k = 0; k < 300; ++k) {
      cv::Mat mask;
      renderer.Render(f.cameras[c].ExposureTime(k), 0, &mask, nullptr);
      MaskSummary summary;
      HullPayload payload;
      payload.hull = ComputeSilhouetteHull(mask, &summary);
      payload.foreground_pixels = summary.foreground_pixels;
      sizes.push_back(EncodeHull(payload).size());
    }
  }
  std::sort(sizes.begin(), sizes.end());
  for (auto _ : state)
    benchmark::DoNotOptimize(sizes.data());
  state.counters["payload_median_bytes"] = static_cast<double>(sizes[sizes.size() / 2]);
  state.counters["payload_max_bytes"] = static_cast<double>(sizes.back());
}
BENCHMARK(BM_HullFrameBytes)->Iterations(1);

}  // namespace
}  // namespace silnet

BENCHMARK_MAIN();
