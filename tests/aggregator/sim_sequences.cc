#include "tests/aggregator/sim_sequences.h"

#include <optional>

#include "node/pipeline/frame_processor.h"
#include "shared/silhouette/hull_codec.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "silnet.h"
#include "sim/render/camera_renderer.h"

namespace silnet::aggregator::testing {
namespace {

// Renders one image of camera `c` at its frame `k` into `image` (empty = dropped frame).
using FrameRenderer = std::function<void(const sim::CameraRenderer& renderer, size_t c, int k,
                                         std::mt19937_64* rng, cv::Mat* image)>;

SimCapture Capture(const sim::CameraNetworkOptions& network, const sim::SceneOptions& scene_options,
                   int frames, node::SegmentationMethod method, const FrameRenderer& render,
                   const sim::CameraMove* move = nullptr) {
  SimCapture capture;
  capture.cameras = sim::MakeCameraNetwork(network);
  capture.cameras_at_end = capture.cameras;
  if (move != nullptr) {
    SILNET_CHECK(move->camera >= 0 && move->camera < static_cast<int>(capture.cameras.size()));
    capture.cameras_at_end[static_cast<size_t>(move->camera)] =
        sim::MovedCamera(capture.cameras[static_cast<size_t>(move->camera)], *move);
  }
  sim::SceneOptions scene = scene_options;
  double begin = 1e9, end = -1e9;
  for (const CameraModel& c : capture.cameras) {
    begin = std::min(begin, c.ExposureTime(-2));
    end = std::max(end, c.ExposureTime(frames + 2));
  }
  scene.time_begin = begin - 1;
  scene.time_end = end + 1;
  capture.scene = std::make_unique<sim::Scene>(scene);
  capture.sequences.resize(capture.cameras.size());
  ParallelFor(capture.cameras.size(), 0, [&](size_t c) {
    const CameraModel& camera = capture.cameras[c];
    const sim::CameraRenderer renderer(camera, *capture.scene, sim::RenderSettings{},
                                       static_cast<int>(c));
    // Only a camera that moves needs a second renderer (each draws its own noise table).
    const bool moves = move != nullptr && move->camera == static_cast<int>(c);
    std::optional<sim::CameraRenderer> renderer_at_end;
    if (moves)
      renderer_at_end.emplace(capture.cameras_at_end[c], *capture.scene, sim::RenderSettings{},
                              static_cast<int>(c));
    const int moves_at = moves ? move->frame : frames;
    node::FrameProcessorOptions options;
    options.camera_id = camera.id;
    options.contour_every = 0;
    options.segmentation.method = method;
    node::FrameProcessor processor(options, camera.width, camera.height);
    std::mt19937_64 rng(1000 + c);
    SilhouetteSequence& seq = capture.sequences[c];
    seq.camera_id = camera.id;
    seq.width = camera.width;
    seq.height = camera.height;
    seq.fps = camera.fps;
    for (int k = 0; k < frames; ++k) {
      node::CapturedFrame frame;
      render(k < moves_at ? renderer : *renderer_at_end, c, k, &rng, &frame.image);
      frame.frame_index = static_cast<uint64_t>(k);
      const node::ProcessedFrame out =
          frame.image.empty() ? processor.Flagged(frame.frame_index, 0, silnet_wire_FRAME_DROPPED)
                              : processor.Process(frame);
      SilhouetteFrame decoded;
      decoded.index = out.hull.frame_index;
      decoded.flags = out.hull.flags;
      HullPayload payload;
      std::string error;
      if (DecodeHull(out.hull.payload, camera.width, camera.height, &payload, &error)) {
        decoded.hull = std::move(payload.hull);
      }
      seq.frames.push_back(std::move(decoded));
    }
    seq.Index();
  });
  return capture;
}

}  // namespace

SimCapture MakeSimCapture(const sim::CameraNetworkOptions& network,
                          const sim::SceneOptions& scene_options, int frames,
                          const MaskDamage& damage) {
  return Capture(network, scene_options, frames, node::SegmentationMethod::kMaskInput,
                 [&](const sim::CameraRenderer& renderer, size_t c, int k, std::mt19937_64* rng,
                     cv::Mat* image) {
                   renderer.Render(renderer.camera().ExposureTime(k), 0, image, nullptr);
                   if (damage) damage(c, k, image, rng);
                 });
}

SimCapture MakeSimCaptureWithMove(const sim::CameraNetworkOptions& network,
                                  const sim::SceneOptions& scene_options, int frames,
                                  const sim::CameraMove& move) {
  return Capture(
      network, scene_options, frames, node::SegmentationMethod::kMaskInput,
      [](const sim::CameraRenderer& renderer, size_t, int k, std::mt19937_64*, cv::Mat* image) {
        renderer.Render(renderer.camera().ExposureTime(k), 0, image, nullptr);
      },
      &move);
}

SimCapture MakeRingWithKnockedCamera(size_t camera, int move_frame, int frames) {
  sim::CameraNetworkOptions network;
  network.seed = 1;
  sim::SceneOptions scene;
  scene.seed = 1;
  sim::CameraMove move;
  move.camera = static_cast<int>(camera);
  move.frame = move_frame;
  move.rotation_deg = 2.0;
  move.axis = Eigen::Vector3d(0.2, 1.0, 0.1);
  move.shift = Eigen::Vector3d(0.05, -0.03, 0.02);
  return MakeSimCaptureWithMove(network, scene, frames, move);
}

std::vector<SilhouetteSequence> SliceSequences(const std::vector<SilhouetteSequence>& sequences,
                                               uint64_t first, uint64_t count) {
  std::vector<SilhouetteSequence> out;
  for (const SilhouetteSequence& s : sequences) {
    SilhouetteSequence slice = s;
    std::erase_if(slice.frames, [&](const SilhouetteFrame& f) {
      return f.index < first || f.index >= first + count;
    });
    slice.Index();
    out.push_back(std::move(slice));
  }
  return out;
}

SimCapture MakeSegmentedSimCapture(const sim::CameraNetworkOptions& network,
                                   const sim::SceneOptions& scene_options, int frames) {
  return Capture(
      network, scene_options, frames, node::SegmentationMethod::kMedian,
      [](const sim::CameraRenderer& renderer, size_t, int k, std::mt19937_64*, cv::Mat* image) {
        renderer.Render(renderer.camera().ExposureTime(k), static_cast<uint64_t>(k), nullptr,
                        image);
      });
}

std::vector<CameraModel> UncalibratedCopies(const std::vector<CameraModel>& truth) {
  std::vector<CameraModel> out;
  for (const CameraModel& c : truth) {
    CameraModel t;
    t.id = c.id;
    t.width = c.width;
    t.height = c.height;
    t.fps = c.fps;
    out.push_back(t);
  }
  return out;
}

}  // namespace silnet::aggregator::testing
