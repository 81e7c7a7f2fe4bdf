// silnet-aggregator stills: asks the camera nodes of a calibration for a still each, collects
// photos and silhouettes over DDS (re-fetching lost or corrupt chunks), writes them as a
// stills folder with that calibration, and on request builds the stereo model from them.

#include <cstdio>
#include <filesystem>

#include "aggregator/calibration/ground_truth_comparison.h"
#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/ingest/still_collector.h"
#include "aggregator/ingest/still_views.h"
#include "aggregator/stereo/stereo_job.h"
#include "aggregator/stereo/stills_folder.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct StillsArgs {
  std::string out, calibration, truth;
  double at_s = -1.0;  // reference time of the still, seconds (negative: each node's next frame)
  double timeout_s = 30.0, discovery_s = 5.0;
  bool stereo = false;
  int domain = -1;
  bool loopback = false;
};

// Simulation only: brings the views' cameras into the frame of the true stills folder `truth`
// (its calibration.yaml) and copies its gt_surface.ply beside the stills, so the stereo job
// scores the model against the true surface; says how far the calibration in use is off.
void ScoreAgainstTruth(const std::filesystem::path& truth, const std::filesystem::path& out,
                       StereoViews* views) {
  const std::vector<CameraModel> true_cameras = LoadCalibration(truth / "calibration.yaml");
  const std::vector<CameraModel> used = views->Cameras();
  const CalibrationErrors errors =
      CompareWithGroundTruth(used, std::vector<bool>(used.size(), true), true_cameras);
  std::printf(
      "  the calibration in use against the truth: rotation %.3f deg median (%.3f max), "
      "focal length %.2f %% median\n",
      errors.median_rotation_deg, errors.max_rotation_deg, 100.0 * errors.median_focal_rel);
  const std::vector<CameraModel> aligned = AlignedToGroundTruth(used, true_cameras);
  for (size_t i = 0; i < aligned.size(); ++i)
    views->views[i].camera = aligned[i];
  std::filesystem::copy_file(truth / "gt_surface.ply", out / "gt_surface.ply",
                             std::filesystem::copy_options::overwrite_existing);
}

int RunStills(const StillsArgs& args) {
  const std::vector<CameraModel> cameras = LoadCalibration(args.calibration);
  StillCollectorOptions options;
  options.domain = dds::DomainConfig::FromEnvironment();
  if (args.domain >= 0) options.domain.domain_id = static_cast<uint32_t>(args.domain);
  if (args.loopback) options.domain.loopback = true;
  options.timeout = std::chrono::milliseconds(static_cast<int64_t>(args.timeout_s * 1000));
  options.discovery = std::chrono::milliseconds(static_cast<int64_t>(args.discovery_s * 1000));
  for (const CameraModel& camera : cameras) {
    options.targets.push_back(
        StillTarget{camera.id, args.at_s >= 0 ? FirstFrameAtOrAfter(camera, args.at_s) : 0});
  }
  const auto run = RunWithProgress("stills", [&](Progress* progress) {
    progress->Restart("stills", options.targets.size());
    return CollectStills(options, progress);
  });
  if (!run) return 130;
  const StillCollection& collection = *run;
  const std::filesystem::path out = args.out;
  std::filesystem::create_directories(out);
  WriteStillSummary(out / "stills.yaml", collection);
  StereoViews views = StillViews(collection, cameras);
  for (const std::string& warning : views.warnings)
    std::printf("  %s\n", warning.c_str());
  std::printf("stills: %zu of %zu cameras answered with a complete still in %.1f s -> %s\n",
              views.views.size(), cameras.size(), collection.seconds, out.string().c_str());
  if (views.views.size() < 2) {
    std::printf("stills: too few stills for a model\n");
    return 3;
  }
  if (!args.truth.empty()) ScoreAgainstTruth(args.truth, out, &views);
  WriteStillsFolder(out, views);
  if (!args.stereo) return 0;
  StereoJobConfig config;
  config.input = out;
  config.calibration = out / "calibration.yaml";
  config.output = out / "stereo";
  const auto model =
      RunWithProgress("stereo", [&](Progress* progress) { return RunStereoJob(config, progress); });
  if (!model) return 130;
  return PrintStereoResult(*model, config.output.string());
}

}  // namespace

Command AddStillsCommand(CLI::App& app) {
  auto args = std::make_shared<StillsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stills", "ask the camera nodes for a still each and collect them as a stills folder");
  cmd->add_option("out", args->out, "output stills folder")->required();
  cmd->add_option("--calib", args->calibration,
                  "calibration.yaml of the cameras to ask (written beside the stills, carried "
                  "over to the stills' resolution)")
      ->required();
  cmd->add_option("--at", args->at_s,
                  "reference time of the still in seconds; each node takes its first frame at "
                  "or after it (its offset from the calibration); default: each node's next "
                  "frame");
  cmd->add_option("--timeout", args->timeout_s, "seconds to wait for the stills")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--discovery", args->discovery_s, "seconds to wait for the nodes to appear")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--stereo", args->stereo, "then build the stereo model into <out>/stereo");
  cmd->add_option("--truth", args->truth,
                  "simulation only: the true stills folder of the subject (silnet-sim stills "
                  "--cameras-from: calibration.yaml, gt_surface.ply); the cameras are aligned "
                  "to it and the model scored against its surface")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--domain", args->domain, "DDS domain id (default: SILNET_DDS_DOMAIN or 0)");
  cmd->add_flag("--loopback", args->loopback, "DDS on 127.0.0.1 only");
  return {cmd, [args] { return RunStills(*args); }};
}

}  // namespace silnet::aggregator::cli
