// silnet-aggregator live: ingest, calibrate once enough motion was seen, publish, build the
// hulls of the frames that follow, and write the report (aggregator/live/live_job.h).

#include <spdlog/spdlog.h>

#include <cstdio>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/live/live_job.h"
#include "aggregator/live/live_report.h"
#include "aggregator/live/service_control.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct LiveArgs {
  std::string out, ground_truth;
  int cameras = 0, calibrate_after = 400, hull_frames = 30, hull_gap = 10, attempts = 3;
  int motion_window = 60, reestimate_frames = 240;
  double idle_exit_s = 5.0, give_up_s = 60.0, rig_radius = 1.0;
  bool no_publish = false, voxels = false, overlays = false, serve = false, continuous = false;
  bool stills = false;
  std::string stills_truth, distortion = "auto";
  double stills_timeout_s = 30.0, stills_at_s = -1.0;
  PairwiseArgs pairwise;
};

int RunLive(const LiveArgs& args) {
  LiveJobOptions options;
  options.output = args.out;
  options.domain = dds::DomainConfig::FromEnvironment();
  options.expected_cameras = args.cameras;
  options.calibrate_after_frames = args.calibrate_after;
  options.max_calibration_attempts = args.attempts;
  options.hull_frames = args.hull_frames;
  options.hull_gap_frames = args.hull_gap;
  options.continuous_hulls = args.continuous;
  options.ground_truth = args.ground_truth;
  options.publish = !args.no_publish;
  options.idle_exit_s = args.idle_exit_s;
  options.give_up_s = args.give_up_s;
  options.serve = args.serve;
  options.calibrate.pairwise = args.pairwise.Options();
  options.calibrate.calibration.rig_radius = args.rig_radius;
  ApplyDistortionSetting(args.distortion, &options.calibrate.calibration);
  options.motion.window_frames = args.motion_window;
  options.motion.reestimate_frames = args.reestimate_frames;
  options.motion.moved.pair = options.calibrate.pairwise.pair;
  options.hulls.polyhedral = !args.voxels;
  options.hulls.overlays = args.overlays;
  options.stills = args.stills;
  options.stills_truth = args.stills_truth;
  options.stills_timeout_s = args.stills_timeout_s;
  options.stills_at_s = args.stills_at_s;
  if (args.stills_at_s >= 0) options.stills = true;
  if (!args.ground_truth.empty() && !std::filesystem::is_regular_file(args.ground_truth))
    throw InputError("--ground-truth " + args.ground_truth + " is not a file");
  const LivePidFile pid_file(options.output);
  const LiveJobResult result = RunLiveJob(
      options, [] { return StopRequested(); }, [] { return TakeRecalibrationRequest(); },
      [] { return TakeStillsSignal(); });
  WriteLiveReport(options.output, result);
  std::printf("%s", LiveSummary(options.output, result).c_str());
  if (StopRequested() && !args.serve) return 130;
  return result.failure.empty() ? 0 : 3;
}

}  // namespace

Command AddLiveCommand(CLI::App& app) {
  auto args = std::make_shared<LiveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "live", "ingest, calibrate once enough motion was seen, publish, build hulls, report");
  cmd->add_option("-o,--out", args->out,
                  "output folder: session/, calibration/, hulls/, report.html")
      ->required();
  cmd->add_option("--cameras", args->cameras,
                  "wait for this many cameras (0: those that show up within 3 s of each other)")
      ->capture_default_str();
  cmd->add_option("--calibrate-after", args->calibrate_after,
                  "frames every camera must stream before the first calibration attempt")
      ->capture_default_str();
  cmd->add_option("--attempts", args->attempts,
                  "calibration attempts, each on 1.5x the frames of the one before")
      ->capture_default_str();
  cmd->add_option("--hull-frames", args->hull_frames,
                  "frames to build hulls of (per batch with --hulls-continuous; 0: none)")
      ->capture_default_str();
  cmd->add_flag("--hulls-continuous", args->continuous,
                "keep building hulls, batch after batch, of every frame that arrives");
  cmd->add_option("--hull-gap", args->hull_gap,
                  "frames between the calibration window and the first hull frame")
      ->capture_default_str();
  cmd->add_option("--ground-truth", args->ground_truth,
                  "a simulation's ground_truth.yaml to compare the calibration with");
  cmd->add_option("--rig-radius", args->rig_radius,
                  "world scale: mean distance of the cameras from their centroid")
      ->capture_default_str();
  AddDistortionOption(cmd, &args->distortion);
  cmd->add_option("--motion-window", args->motion_window,
                  "check for moved cameras every this many frames once calibrated (0: never)")
      ->capture_default_str();
  cmd->add_option("--reestimate-frames", args->reestimate_frames,
                  "frames after a move a moved camera is re-estimated from")
      ->capture_default_str();
  cmd->add_flag("--no-publish", args->no_publish, "do not publish the calibration on DDS");
  cmd->add_flag("--serve", args->serve,
                "run as a service until SIGINT/SIGTERM; SIGHUP (or `silnet-aggregator recalibrate "
                "OUT`) recalibrates on the newest frames, `silnet-aggregator stills OUT` takes "
                "stills and builds their model into the report");
  cmd->add_flag("--voxels", args->voxels,
                "carve voxel hulls instead of the exact polyhedral ones (their fallback)");
  cmd->add_flag("--overlays", args->overlays, "hull reprojection overlays per view");
  cmd->add_flag("--stills", args->stills,
                "once the streams end, ask the nodes for stills and build the stereo model "
                "(OUT/stills, in the report)");
  cmd->add_option("--stills-at", args->stills_at_s,
                  "ask for the stills of this reference instant (seconds) as soon as the "
                  "calibration is in use, and build the model while ingesting goes on")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--stills-timeout", args->stills_timeout_s, "seconds to wait for the stills")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--stills-truth", args->stills_truth,
                  "simulation: the true stills folder of the subject (silnet-sim stills "
                  "--cameras-from) to align the calibration to and score the model against")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--idle-exit", args->idle_exit_s,
                  "once hulls are built, exit after this many seconds without samples")
      ->capture_default_str();
  cmd->add_option("--give-up-after", args->give_up_s,
                  "exit after this many seconds without samples while waiting for frames")
      ->capture_default_str();
  args->pairwise.AddTo(cmd);
  return {cmd, [args] { return RunLive(*args); }};
}

}  // namespace silnet::aggregator::cli
