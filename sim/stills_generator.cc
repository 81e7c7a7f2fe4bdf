#include "sim/stills_generator.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/io/png_writer.h"
#include "shared/io/point_cloud_ply.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "sim/dataset_generator.h"
#include "sim/ground_truth.h"
#include "sim/scene/outer_surface.h"
#include "sim/scene/scene.h"

namespace silnet::sim {
namespace {

// Lowest and highest z of the primitives.
std::pair<double, double> HeightRange(const std::vector<Primitive>& primitives) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Primitive& p : primitives) {
    low = std::min(low, p.BoundingCenter().z() - p.HalfExtents().z());
    high = std::max(high, p.BoundingCenter().z() + p.HalfExtents().z());
  }
  return {low, high};
}

}  // namespace

CameraNetworkOptions StillsNetworkDefaults() {
  CameraNetworkOptions network;
  network.cameras = 16;
  network.max_offset = 0.0;
  network.fps_spread = 0.0;
  network.aim_jitter = 0.05;
  return network;
}

std::string StillsOptions::Validate() const {
  if (!(fill > 0.1 && fill <= 1.0)) return "fill must lie in (0.1, 1]";
  if (radius != 0.0 && !(radius > 0.5)) return "camera distance must exceed 0.5 m (or be 0)";
  if (!(surface_spacing >= 0.0 && surface_spacing < 0.1)) return "surface spacing must be 0..0.1 m";
  if (render.noise_sigma < 0.0 || render.noise_sigma > 40.0) return "noise must be 0..40 DN";
  return {};
}

std::filesystem::path StillPath(const std::filesystem::path& dir, const std::string& camera,
                                int frame) {
  return dir / camera / "stills" / DatasetLayout::ImageName(frame);
}

std::filesystem::path StillMaskPath(const std::filesystem::path& dir, const std::string& camera,
                                    int frame) {
  return dir / camera / "masks" / DatasetLayout::ImageName(frame);
}

std::filesystem::path BackgroundPath(const std::filesystem::path& dir, const std::string& camera) {
  return dir / camera / "background.png";
}

StillsSummary GenerateStills(const StillsOptions& options, const std::filesystem::path& output,
                             Progress* progress) {
  if (const std::string reason = options.Validate(); !reason.empty()) throw InputError(reason);
  const auto start = std::chrono::steady_clock::now();
  RequireWritableOutput(output, options.overwrite);

  SceneOptions scene_options;
  scene_options.subject = SubjectKind::kStillsStatue;
  scene_options.walk_radius = 0.0;
  scene_options.time_begin = -1.0;
  scene_options.time_end = 1.0;
  scene_options.lighting_changes = false;
  scene_options.seed = options.seed;
  const Scene scene(scene_options);
  const std::vector<Primitive> statue = scene.PrimitivesAt(0.0);
  const auto [low, high] = HeightRange(statue);

  CameraNetworkOptions network = options.network;
  network.seed = options.seed;
  network.target_height = 0.5 * (low + high);
  const double focal =
      0.5 * network.width / std::tan(0.5 * network.horizontal_fov_deg * std::numbers::pi / 180.0);
  network.radius = options.radius > 0.0 ? options.radius
                                        : focal * (high - low) / (options.fill * network.height);
  StillsSummary summary;
  summary.cameras = options.cameras.empty() ? MakeCameraNetwork(network) : options.cameras;
  const Eigen::Vector3d target(0.0, 0.0, network.target_height);
  size_t pixels = 0;
  for (const CameraModel& c : summary.cameras) {
    summary.footprint += (c.Center() - target).norm() / c.K(0, 0);
    summary.radius += (c.Center() - target).norm() / static_cast<double>(summary.cameras.size());
    pixels = std::max(pixels, static_cast<size_t>(c.width) * static_cast<size_t>(c.height));
  }
  summary.footprint /= static_cast<double>(summary.cameras.size());
  summary.surface_spacing =
      options.surface_spacing > 0.0 ? options.surface_spacing : 0.5 * summary.footprint;

  for (const CameraModel& c : summary.cameras) {
    std::filesystem::create_directories(StillPath(output, c.id).parent_path());
    std::filesystem::create_directories(StillMaskPath(output, c.id).parent_path());
  }
  RenderSettings render = options.render;
  render.seed = options.seed;
  const auto noise = std::make_shared<const SensorNoise>(render.noise_sigma, pixels * 3,
                                                         MixSeed(render.seed, 0x5E5u));
  std::atomic<size_t> bytes{0}, images{0};
  ParallelFor(summary.cameras.size(), options.threads, [&](size_t i) {
    if (progress != nullptr && progress->cancelled()) throw std::runtime_error("cancelled");
    const CameraModel& c = summary.cameras[i];
    const CameraRenderer renderer(c, scene, render, static_cast<int>(i), noise);
    cv::Mat mask, colour;
    renderer.Render(0.0, MixSeed(render.seed, i, 0), &mask, &colour);
    bytes += WritePngFast(StillPath(output, c.id), colour);
    bytes += WritePngFast(StillMaskPath(output, c.id), mask);
    images += 2;
    if (options.write_backgrounds) {
      cv::Mat background;
      renderer.RenderPrimitives({}, scene.environment().LightGain(0.0), MixSeed(render.seed, i, 1),
                                nullptr, &background);
      bytes += WritePngFast(BackgroundPath(output, c.id), background);
      ++images;
    }
    if (progress != nullptr) progress->Advance();
  });

  SaveCalibration(output / "calibration.yaml", summary.cameras);
  GroundTruthScene truth;
  truth.subject = ToString(SubjectKind::kStillsStatue);
  truth.layout = options.cameras.empty() ? ToString(network.layout) : "given";
  truth.seed = options.seed;
  truth.reference_fps = network.fps;
  truth.frames = 1;
  WriteGroundTruth(output / "ground_truth.yaml", truth, summary.cameras, scene);

  const std::vector<SurfacePoint> surface =
      SampleOuterSurface(statue, summary.surface_spacing, MixSeed(options.seed, 0x9D5u));
  OrientedPointCloud cloud;
  cloud.comments = {"silnet simulated stills: outer surface of the stills statue",
                    fmt::format("spacing_m {:.6f}", summary.surface_spacing),
                    fmt::format("footprint_m {:.6f}", summary.footprint)};
  cloud.points.reserve(surface.size());
  cloud.normals.reserve(surface.size());
  for (const SurfacePoint& s : surface) {
    cloud.points.push_back(s.position.cast<float>());
    cloud.normals.push_back(s.normal.cast<float>());
  }
  bytes += WritePointCloudPly(output / "gt_surface.ply", cloud);
  if (progress != nullptr) progress->Finish();
  summary.surface_points = surface.size();
  summary.images_written = images.load();
  summary.bytes_written = bytes.load();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace silnet::sim
