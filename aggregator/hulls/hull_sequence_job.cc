#include "aggregator/hulls/hull_sequence_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/silhouette_interpolation.h"
#include "aggregator/hulls/silhouette_source.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Fractional frame indices closer than this to an integer count as that integer.
constexpr double kIntegerTolerance = 1e-6;

// Where camera c's silhouette of one reference frame comes from: frame `k` blended towards
// frame k + 1 by `fraction` (0 = frame k alone).
struct MaskSource {
  int k = 0;
  double fraction = 0;
};

MaskSource SourceFor(double frame, bool interpolate) {
  if (!interpolate) return {static_cast<int>(std::lround(frame)), 0.0};
  const double nearest = std::round(frame);
  if (std::abs(frame - nearest) < kIntegerTolerance) return {static_cast<int>(nearest), 0.0};
  const double k = std::floor(frame);
  return {static_cast<int>(k), frame - k};
}

cv::Mat MaskAt(const SilhouetteSource& silhouettes, const CameraModel& camera,
               const MaskSource& source) {
  const cv::Mat first = silhouettes.Mask(camera, source.k);
  if (source.fraction == 0) return first;
  return InterpolateSilhouette(first, silhouettes.Mask(camera, source.k + 1), source.fraction);
}

// Every calibration camera must have silhouettes; input cameras without a calibration are
// left out with a warning.
void CheckCameras(const SilhouetteSource& silhouettes, const std::vector<CameraModel>& cameras,
                  const std::filesystem::path& calibration) {
  if (cameras.empty()) throw InputError(fmt::format("{} has no cameras", calibration.string()));
  std::set<std::string> calibrated;
  for (const CameraModel& camera : cameras) {
    calibrated.insert(camera.id);
    if (silhouettes.FrameCount(camera.id) == 0) {
      throw InputError(fmt::format("camera {} of {} has no silhouettes in {} (expected {})",
                                   camera.id, calibration.string(), silhouettes.root().string(),
                                   silhouettes.Where(camera.id, 0)));
    }
  }
  // A camera the calibration could not place is left out, not fatal.
  for (const std::string& id : silhouettes.CameraIds()) {
    if (!calibrated.count(id)) {
      spdlog::warn("camera {} of {} is not in the calibration {}; building hulls without it", id,
                   silhouettes.root().string(), calibration.string());
    }
  }
}

// "; usable reference frames A:B" (or a note that there are none), for error messages.
std::string UsableRange(const SilhouetteSource& silhouettes,
                        const std::vector<CameraModel>& cameras, bool interpolate) {
  const auto usable = UsableReferenceFrames(silhouettes, cameras, interpolate);
  if (!usable) return "; no reference frame is seen by every camera";
  return fmt::format("; usable reference frames {}:{}", usable->first, usable->second);
}

// The mask sources of every camera for every reference frame; InputError if one is missing.
std::vector<std::vector<MaskSource>> PlanSources(const SilhouetteSource& silhouettes,
                                                 const std::vector<CameraModel>& cameras,
                                                 const std::vector<double>& times, bool interpolate,
                                                 int first_frame) {
  std::vector<std::vector<MaskSource>> plan(times.size(), std::vector<MaskSource>(cameras.size()));
  for (size_t c = 0; c < cameras.size(); ++c) {
    const int count = silhouettes.FrameCount(cameras[c].id);
    for (size_t f = 0; f < times.size(); ++f) {
      const double frame = cameras[c].FrameAt(times[f]);
      const MaskSource source = SourceFor(frame, interpolate);
      const int last_needed = source.fraction > 0 ? source.k + 1 : source.k;
      if (source.k < 0 || last_needed >= count) {
        throw InputError(fmt::format(
            "reference frame {} is out of range: camera {} would need its frame {:.3f} but has "
            "silhouettes 0..{}{}",
            first_frame + static_cast<int>(f), cameras[c].id, frame, count - 1,
            UsableRange(silhouettes, cameras, interpolate)));
      }
      plan[f][c] = source;
    }
  }
  return plan;
}

bool AnyFractional(const std::vector<CameraModel>& cameras, const std::vector<double>& times) {
  for (const CameraModel& camera : cameras) {
    for (double time : times) {
      const double frame = camera.FrameAt(time);
      if (std::abs(frame - std::round(frame)) >= kIntegerTolerance) return true;
    }
  }
  return false;
}

// The exposure times of `reference`'s frames [first, last).
std::vector<double> ReferenceTimes(const CameraModel& reference, int first, int last) {
  std::vector<double> times;
  for (int frame = first; frame < last; ++frame)
    times.push_back(reference.ExposureTime(frame));
  return times;
}

// Every reference frame all cameras cover: with the frame after each camera's own too when
// `interpolate` says so or, unset, when those frames fall between the cameras' frames.
std::pair<int, int> EveryCoveredFrame(const SilhouetteSource& silhouettes,
                                      const std::vector<CameraModel>& cameras,
                                      std::optional<bool> interpolate) {
  auto usable = UsableReferenceFrames(silhouettes, cameras, interpolate.value_or(false));
  if (usable && !interpolate.has_value() &&
      AnyFractional(cameras, ReferenceTimes(cameras[ReferenceCameraIndex(cameras)], usable->first,
                                            usable->second))) {
    usable = UsableReferenceFrames(silhouettes, cameras, true);
  }
  if (!usable) {
    throw InputError(fmt::format(
        "no reference frame is seen by every camera of the calibration in {} (their time "
        "offsets leave no frame in common)",
        silhouettes.root().string()));
  }
  spdlog::info("hulls: reference frames {}:{}, every frame all {} cameras cover", usable->first,
               usable->second, cameras.size());
  return *usable;
}

std::string PlyName(int frame) {
  return fmt::format("frame_{:06d}.ply", frame);
}

HullFrameResult BuildFrame(const SilhouetteSource& silhouettes,
                           const std::vector<CameraModel>& cameras,
                           const std::vector<MaskSource>& sources, const VoxelHullOptions& carve,
                           const HullSequenceConfig& config, int frame) {
  HullFrameResult result;
  result.frame = frame;
  std::vector<cv::Mat> masks(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c)
    masks[c] = MaskAt(silhouettes, cameras[c], sources[c]);
  TriangleMesh mesh;
  if (config.options.polyhedral) {
    PolyhedralHullOptions exact_options;
    exact_options.threads = carve.threads;
    // A subject partly outside one view stays exact while the other views bound it.
    exact_options.border_extension = 0.5;
    PolyhedralHullResult exact = ComputePolyhedralHull(cameras, masks, exact_options);
    if (exact.success) {
      mesh = std::move(exact.mesh);
      result.method = "polyhedral";
      result.gaps_filled = exact.stats.gaps_filled;
      result.contours_perturbed = exact.stats.contours_perturbed;
    } else {
      result.polyhedral_failure = exact.reason;
      spdlog::warn("frame {}: polyhedral hull failed ({}); carving voxels", frame, exact.reason);
    }
  }
  if (result.method.empty()) {
    const VoxelHullResult hull = CarveVoxelHull(cameras, masks, carve);
    if (!hull.success) {
      result.reason = hull.reason;
      return result;
    }
    mesh = ExtractBoundaryMesh(hull.grid);
    result.method = "voxel";
  }
  if (mesh.triangles.empty()) {
    result.reason = "the silhouettes do not intersect: the hull is empty";
    return result;
  }
  result.success = true;
  result.vertices = mesh.vertices.size();
  result.triangles = mesh.triangles.size();
  result.closed_manifold = CheckClosedManifold(mesh).closed_manifold;
  result.volume_m3 = MeshVolume(mesh);
  result.file = PlyName(frame);
  WritePlyMesh((config.output / result.file).string(), mesh);
  for (size_t c = 0; c < cameras.size(); ++c) {
    const cv::Mat rendered = RenderMeshSilhouette(mesh, cameras[c]);
    ViewReprojection view = CompareWithSilhouette(rendered, masks[c]);
    view.camera_id = cameras[c].id;
    result.views.push_back(view);
    if (config.options.overlays) {
      const std::string name = fmt::format("frame_{:06d}_{}.png", frame, cameras[c].id);
      WriteReprojectionOverlay((config.output / "overlays" / name).string(), rendered, masks[c]);
    }
  }
  return result;
}

// The default voxel size from the first frame's viewing-cone bounds.
double DefaultVoxelSize(const SilhouetteSource& silhouettes,
                        const std::vector<CameraModel>& cameras,
                        const std::vector<MaskSource>& sources, double divisor) {
  std::vector<cv::Mat> masks(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c)
    masks[c] = MaskAt(silhouettes, cameras[c], sources[c]);
  const ViewingConeBounds bounds = ComputeViewingConeBounds(cameras, masks);
  if (!bounds.success) {
    throw InputError("cannot derive a voxel size from the first frame (" + bounds.reason +
                     "); give one with --voxel");
  }
  return bounds.box.diagonal().norm() / divisor;
}

}  // namespace

void WriteHullIndex(const HullSequenceConfig& config, const HullSequenceResult& result) {
  const std::filesystem::path path = config.output / "hulls.yaml";
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(fmt::format("cannot write {}", path.string()));
  fs << "format_version" << 1;
  fs << "input" << config.input.string() << "calibration" << config.calibration.string();
  fs << "voxel_size" << result.voxel_size << "interpolated"
     << static_cast<int>(result.interpolated);
  fs << "frames"
     << "[";
  for (const HullFrameResult& f : result.frames) {
    fs << "{"
       << "frame" << f.frame << "time" << f.time_s << "success" << static_cast<int>(f.success);
    if (!f.success) {
      fs << "reason" << f.reason << "}";
      continue;
    }
    fs << "file" << f.file << "vertices" << static_cast<int>(f.vertices) << "faces"
       << static_cast<int>(f.triangles) << "closed_manifold" << static_cast<int>(f.closed_manifold)
       << "volume" << f.volume_m3 << "method" << f.method;
    if (!f.polyhedral_failure.empty()) fs << "polyhedral_failure" << f.polyhedral_failure;
    if (f.gaps_filled > 0) fs << "gaps_filled" << static_cast<int>(f.gaps_filled);
    if (f.contours_perturbed) fs << "contours_perturbed" << 1;
    fs << "views"
       << "[";
    for (const ViewReprojection& v : f.views) {
      fs << "{"
         << "camera" << v.camera_id << "silhouette_pixels" << static_cast<int>(v.silhouette_pixels)
         << "missed_fraction" << v.missed_fraction << "extra_fraction" << v.spurious_fraction
         << "}";
    }
    fs << "]"
       << "}";
  }
  fs << "]";
}

bool HullSequenceOptions::IsValid(std::string* reason) const {
  if (!(voxel_size >= 0)) {
    *reason = "the voxel size must be positive (or 0 for the default)";
    return false;
  }
  if (!(voxels_per_diagonal >= 1)) {
    *reason = "voxels_per_diagonal must be at least 1";
    return false;
  }
  if (threads < 0) {
    *reason = "threads must be >= 0";
    return false;
  }
  return true;
}

double HullSequenceResult::MeanMissed() const {
  double sum = 0;
  size_t n = 0;
  for (const HullFrameResult& f : frames) {
    for (const ViewReprojection& v : f.views) {
      sum += v.missed_fraction;
      ++n;
    }
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

double HullSequenceResult::MeanSpurious() const {
  double sum = 0;
  size_t n = 0;
  for (const HullFrameResult& f : frames) {
    for (const ViewReprojection& v : f.views) {
      sum += v.spurious_fraction;
      ++n;
    }
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

size_t HullSequenceResult::Succeeded() const {
  return static_cast<size_t>(std::count_if(frames.begin(), frames.end(),
                                           [](const HullFrameResult& f) { return f.success; }));
}

bool HullSequenceResult::AllClosedManifold() const {
  return std::all_of(frames.begin(), frames.end(),
                     [](const HullFrameResult& f) { return f.success && f.closed_manifold; });
}

size_t ReferenceCameraIndex(const std::vector<CameraModel>& cameras) {
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (cameras[c].time_offset == 0.0) return c;
  }
  return 0;
}

std::optional<std::pair<int, int>> UsableReferenceFrames(const SilhouetteSource& silhouettes,
                                                         const std::vector<CameraModel>& cameras,
                                                         bool interpolate) {
  if (cameras.empty()) return std::nullopt;
  const CameraModel& reference = cameras[ReferenceCameraIndex(cameras)];
  int first = std::numeric_limits<int>::min(), last = std::numeric_limits<int>::max();
  for (const CameraModel& camera : cameras) {
    // Camera frame f(r) = a r + b of reference frame r; a > 0. SourceFor needs f in
    // [0, count - 1] to interpolate (an integer f within the tolerance reads one frame), and
    // f rounding into 0..count-1, f in (-0.5, count - 0.5), to take the nearest frame.
    const double b = camera.FrameAt(reference.ExposureTime(0));
    const double a = camera.FrameAt(reference.ExposureTime(1)) - b;
    const double count = silhouettes.FrameCount(camera.id);
    const double low = interpolate ? (0 - b) / a - kIntegerTolerance : (-0.5 - b) / a;
    const double high =
        interpolate ? (count - 1 - b) / a + kIntegerTolerance : (count - 0.5 - b) / a;
    first = std::max(first, static_cast<int>(interpolate ? std::ceil(low) : std::floor(low) + 1));
    last = std::min(last, static_cast<int>(interpolate ? std::floor(high) : std::ceil(high) - 1));
  }
  if (last < first) return std::nullopt;
  return std::pair<int, int>(first, last + 1);
}

HullSequenceResult RunHullSequenceJob(const HullSequenceConfig& config, Progress* progress) {
  return RunHullSequenceJob(config, *OpenSilhouetteSource(config.input), progress);
}

HullSequenceResult RunHullSequenceJob(const HullSequenceConfig& config,
                                      const SilhouetteSource& silhouettes, Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!config.options.IsValid(&why)) throw InputError(why);
  if (!config.every_covered_frame && config.last_frame <= config.first_frame) {
    throw InputError(fmt::format("the frame range {}:{} is empty (frames A:B run A..B-1)",
                                 config.first_frame, config.last_frame));
  }
  const std::vector<CameraModel> cameras = LoadCalibration(config.calibration);
  CheckCameras(silhouettes, cameras, config.calibration);

  const CameraModel& reference = cameras[ReferenceCameraIndex(cameras)];
  const auto [first_frame, last_frame] =
      config.every_covered_frame
          ? EveryCoveredFrame(silhouettes, cameras, config.options.interpolate)
          : std::pair<int, int>(config.first_frame, config.last_frame);
  const size_t n = static_cast<size_t>(last_frame - first_frame);
  HullSequenceResult result;
  result.frames.resize(n);
  const std::vector<double> times = ReferenceTimes(reference, first_frame, last_frame);
  for (size_t f = 0; f < n; ++f) {
    result.frames[f].frame = first_frame + static_cast<int>(f);
    result.frames[f].time_s = times[f];
    result.frames[f].reason = "cancelled";
  }
  result.interpolated = config.options.interpolate.value_or(AnyFractional(cameras, times));
  const auto plan = PlanSources(silhouettes, cameras, times, result.interpolated, first_frame);

  result.voxel_size =
      config.options.voxel_size > 0
          ? config.options.voxel_size
          : DefaultVoxelSize(silhouettes, cameras, plan[0], config.options.voxels_per_diagonal);
  std::filesystem::create_directories(config.output);
  if (config.options.overlays) std::filesystem::create_directories(config.output / "overlays");

  // Frames run in parallel; a lone frame carves (or computes its cone faces) on all threads
  // instead.
  const int frame_threads = ResolveThreadCount(config.options.threads, n);
  VoxelHullOptions carve;
  carve.voxel_size = result.voxel_size;
  carve.threads = frame_threads > 1 ? 1 : config.options.threads;
  if (progress) progress->Restart("hulls", n);
  ParallelFor(n, frame_threads, [&](size_t f) {
    if (progress && progress->cancelled()) return;
    const double time = result.frames[f].time_s;
    result.frames[f] =
        BuildFrame(silhouettes, cameras, plan[f], carve, config, result.frames[f].frame);
    result.frames[f].time_s = time;
    if (progress) progress->Advance();
  });
  WriteHullIndex(config, result);
  if (progress) progress->Finish();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace silnet::aggregator
