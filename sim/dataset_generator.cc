#include "sim/dataset_generator.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>

#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/io/png_writer.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "sim/ground_truth.h"

namespace silnet::sim {

std::string SimulationOptions::Validate() const {
  if (frames < 1 || frames > 1000000) return "frames must be between 1 and 1000000";
  if (!write_masks && !write_frames) return "nothing to write: enable masks or frames";
  if (scene.count < 1 || scene.count > 8) return "between 1 and 8 subjects";
  if (!(scene.walk_radius >= 0.0 && scene.walk_radius < network.radius - 0.5)) {
    return "walk radius must be non-negative and keep 0.5 m away from the cameras";
  }
  if (render.noise_sigma < 0.0 || render.noise_sigma > 40.0) return "noise must be 0..40 DN";
  std::vector<bool> moved(static_cast<size_t>(std::max(network.cameras, 0)), false);
  for (const CameraMove& m : moves) {
    if (m.camera < 0 || m.camera >= network.cameras) return "a camera move names no camera";
    if (m.frame <= 0 || m.frame >= frames) return "a camera move must happen within the capture";
    if (moved[static_cast<size_t>(m.camera)]) return "at most one move per camera";
    moved[static_cast<size_t>(m.camera)] = true;
  }
  return {};
}

SceneOptions SceneForCameras(const SimulationOptions& options,
                             const std::vector<CameraModel>& cameras) {
  SceneOptions scene = options.scene;
  double begin = std::numeric_limits<double>::infinity(), end = -begin;
  for (const CameraModel& c : cameras) {
    begin = std::min(begin, c.ExposureTime(-1));
    end = std::max(end, c.ExposureTime(options.frames));
  }
  scene.time_begin = begin - 1.0;
  scene.time_end = end + 1.0;
  return scene;
}

void RequireWritableOutput(const std::filesystem::path& output, bool overwrite) {
  std::error_code error;
  if (std::filesystem::exists(output) && !std::filesystem::is_empty(output, error) && !overwrite)
    throw InputError(output.string() + " is not empty (use --force to write into it)");
}

SimulationSummary GenerateDataset(const SimulationOptions& options,
                                  const std::filesystem::path& output, Progress* progress) {
  if (const std::string reason = options.Validate(); !reason.empty()) throw InputError(reason);
  const auto start = std::chrono::steady_clock::now();
  RequireWritableOutput(output, options.overwrite);
  SimulationSummary summary;
  summary.cameras = MakeCameraNetwork(options.network);
  summary.frames = options.frames;
  const Scene scene(SceneForCameras(options, summary.cameras));
  const DatasetLayout layout(output);
  for (const CameraModel& c : summary.cameras) {
    if (options.write_frames) std::filesystem::create_directories(layout.FramesDir(c.id));
    if (options.write_masks) std::filesystem::create_directories(layout.MasksDir(c.id));
  }

  const int threads = options.threads;
  const size_t camera_count = summary.cameras.size();
  const auto noise = std::make_shared<const SensorNoise>(
      options.render.noise_sigma,
      static_cast<size_t>(options.network.width) * static_cast<size_t>(options.network.height) * 3,
      MixSeed(options.render.seed, 0x5E5u));
  std::vector<std::unique_ptr<CameraRenderer>> renderers(camera_count);
  ParallelFor(camera_count, threads, [&](size_t i) {
    renderers[i] = std::make_unique<CameraRenderer>(summary.cameras[i], scene, options.render,
                                                    static_cast<int>(i), noise);
  });
  // A moved camera renders through a second renderer from its move on.
  std::vector<std::unique_ptr<CameraRenderer>> moved_renderers(camera_count);
  std::vector<int> moves_at(camera_count, options.frames);
  std::vector<CameraMoveRecord> move_records;
  for (const CameraMove& m : options.moves) {
    const size_t c = static_cast<size_t>(m.camera);
    const CameraModel moved = MovedCamera(summary.cameras[c], m);
    moved_renderers[c] =
        std::make_unique<CameraRenderer>(moved, scene, options.render, m.camera, noise);
    moves_at[c] = m.frame;
    move_records.push_back({m.frame, moved});
    spdlog::info("{} moves at frame {}: turned {:.2f} deg, shifted {:.3f} m", moved.id, m.frame,
                 m.rotation_deg, m.shift.norm());
  }

  std::atomic<size_t> bytes{0}, images{0};
  const size_t tasks = camera_count * static_cast<size_t>(options.frames);
  // Frame-major order keeps all cameras progressing together.
  ParallelFor(tasks, threads, [&](size_t task) {
    if (progress != nullptr && progress->cancelled()) throw std::runtime_error("cancelled");
    const size_t camera = task % camera_count;
    const int frame = static_cast<int>(task / camera_count);
    const CameraRenderer& renderer =
        frame < moves_at[camera] ? *renderers[camera] : *moved_renderers[camera];
    const CameraModel& c = renderer.camera();
    cv::Mat mask, colour;
    renderer.Render(c.ExposureTime(frame),
                    MixSeed(options.render.seed, camera, static_cast<uint64_t>(frame)), &mask,
                    options.write_frames ? &colour : nullptr);
    if (options.write_masks) {
      bytes += WritePngFast(layout.MaskPath(c.id, frame), mask);
      ++images;
    }
    if (options.write_frames) {
      bytes += WritePngFast(layout.FramePath(c.id, frame), colour);
      ++images;
    }
    if (progress != nullptr) progress->Advance();
  });

  GroundTruthScene truth;
  truth.subject = ToString(options.scene.subject);
  truth.subjects = scene.subject_count();
  truth.layout = ToString(options.network.layout);
  truth.seed = options.scene.seed;
  truth.reference_fps = options.network.fps;
  truth.frames = options.frames;
  WriteGroundTruth(layout.GroundTruthPath(), truth, summary.cameras, scene, move_records);
  if (progress != nullptr) progress->Finish();
  summary.images_written = images.load();
  summary.bytes_written = bytes.load();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace silnet::sim
