#include "aggregator/stereo/stills_stage.h"

#include <spdlog/spdlog.h>

#include <opencv2/imgcodecs.hpp>

#include "aggregator/ingest/still_views.h"
#include "aggregator/stereo/stereo_truth.h"
#include "aggregator/stereo/stills_folder.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Brings the views' cameras into the frame of the true stills folder, registered at the
// subject (AlignedAtSubject: the model is scored for its shape, not for where camera centres
// metres away put it), and copies its surface beside the stills; returns how far the
// calibration in use is off.
CalibrationErrors AlignToTruth(const std::filesystem::path& truth, const std::filesystem::path& out,
                               StereoViews* views) {
  const std::vector<CameraModel> true_cameras = LoadCalibration(truth / "calibration.yaml");
  const std::vector<CameraModel> used = views->Cameras();
  const CalibrationErrors errors =
      CompareWithGroundTruth(used, std::vector<bool>(used.size(), true), true_cameras);
  const std::optional<StereoTruth> surface = LoadStereoTruth(truth);
  if (!surface) throw InputError(truth.string() + " has no gt_surface.ply");
  const std::vector<CameraModel> aligned = AlignedAtSubject(used, true_cameras, surface->points);
  for (size_t i = 0; i < aligned.size(); ++i)
    views->views[i].camera = aligned[i];
  std::filesystem::copy_file(truth / "gt_surface.ply", out / "gt_surface.ply",
                             std::filesystem::copy_options::overwrite_existing);
  return errors;
}

// Writes every complete still as <output>/<camera>/background.png; returns how many.
size_t WriteBackgrounds(const std::filesystem::path& output, const StillCollection& collection) {
  size_t written = 0;
  for (const CollectedStill& still : collection.cameras) {
    if (!still.complete) continue;
    const std::filesystem::path dir = output / still.camera_id;
    std::filesystem::create_directories(dir);
    if (!cv::imwrite((dir / "background.png").string(), still.photo))
      throw InputError("cannot write " + (dir / "background.png").string());
    ++written;
  }
  return written;
}

}  // namespace

StillsStageResult RunStillsStage(const StillsStageConfig& config, Progress* progress) {
  if (config.cameras.empty()) throw InputError("no calibrated cameras to ask for stills");
  StillCollectorOptions collect = config.collect;
  if (collect.targets.empty()) {
    for (const CameraModel& camera : config.cameras)
      collect.targets.push_back(StillTarget{camera.id, 0});
  }
  if (progress) progress->Restart("stills", collect.targets.size());
  StillsStageResult result;
  result.collection = CollectStills(collect, progress);
  std::filesystem::create_directories(config.output);
  WriteStillSummary(config.output / "stills.yaml", result.collection);
  if (collect.background) {
    result.views = WriteBackgrounds(config.output, result.collection);
    if (result.views == 0) result.failure = "no camera sent its still of the empty scene";
    return result;
  }
  StereoViews views = StillViews(result.collection, config.cameras);
  result.views = views.views.size();
  result.warnings = views.warnings;
  if (progress && progress->cancelled()) {
    result.failure = "cancelled";
    return result;
  }
  if (views.views.size() < 2) {
    result.failure = fmt::format("{} usable stills: too few for a model", views.views.size());
    return result;
  }
  if (!config.truth.empty()) {
    result.calibration_vs_truth = AlignToTruth(config.truth, config.output, &views);
  }
  WriteStillsFolder(config.output, views);
  if (!config.stereo) return result;
  StereoJobConfig stereo;
  stereo.input = config.output;
  stereo.calibration = config.output / "calibration.yaml";
  stereo.output = config.output / "stereo";
  stereo.threads = config.threads;
  result.stereo = RunStereoJob(stereo, progress);
  if (!result.stereo->success) result.failure = "stereo: " + result.stereo->reason;
  return result;
}

}  // namespace silnet::aggregator
