// silnet-aggregator stills: asks the camera nodes of a calibration for a still each, collects
// photos and silhouettes over DDS (re-fetching lost or corrupt chunks), writes them as a
// stills folder with that calibration, and on request builds the stereo model from them.
// Without a calibration it asks the live job running in the folder to do so with the
// calibration it uses, and follows the job's answer.

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/ingest/still_views.h"
#include "aggregator/live/service_control.h"
#include "aggregator/stereo/stills_stage.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct StillsArgs {
  std::string out, calibration, truth;
  double at_s = -1.0;  // reference time of the still, seconds (negative: each node's next frame)
  double timeout_s = 30.0, discovery_s = 5.0;
  bool stereo = false, no_stereo = false, no_wait = false, background = false;
  int domain = -1;
  bool loopback = false;
};

// Asks the live job in `args.out` for stills and, unless told not to, prints its answers
// until it is done: 0 with a model (or stills without one asked for), 3 if they failed.
int AskLiveJob(const StillsArgs& args) {
  if (!args.truth.empty() || args.domain >= 0 || args.loopback)
    throw InputError(
        "--truth, --domain and --loopback need --calib: the live job uses its own domain and "
        "--stills-truth");
  StillsRequest request;
  request.id =
      fmt::format("{}-{}", getpid(), std::chrono::system_clock::now().time_since_epoch().count());
  request.at_s = args.at_s;
  request.stereo = !args.no_stereo;
  request.background = args.background;
  const int pid = RequestStills(args.out, request);
  std::printf("asked the live job (process %d) for stills into %s/stills\n", pid, args.out.c_str());
  if (args.no_wait) return 0;
  std::string last_state;
  while (!StopRequested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    const std::optional<StillsAnswer> answer = ReadStillsAnswer(args.out);
    const bool answered = answer && answer->id == request.id;
    if (answered && answer->state != last_state) {
      last_state = answer->state;
      std::printf("stills: %s\n%s", answer->state.c_str(), answer->text.c_str());
      std::fflush(stdout);
      if (answer->state == "done") return 0;
      if (answer->state == "failed") return 3;
    }
    if (!RunningLiveJob(args.out)) {
      std::printf("stills: the live job (process %d) ended without answering\n", pid);
      return 3;
    }
  }
  std::printf("stills: stopped waiting; the live job goes on with the request\n");
  return 130;
}

int RunStills(const StillsArgs& args) {
  if (args.calibration.empty()) return AskLiveJob(args);
  if (args.no_stereo || args.no_wait)
    throw InputError("--no-stereo and --no-wait are for asking a live job (without --calib)");
  if (args.background && args.stereo)
    throw InputError("--background takes stills of the empty scene: no model to build");
  StillsStageConfig config;
  config.cameras = LoadCalibration(args.calibration);
  config.output = args.out;
  config.stereo = args.stereo;
  config.collect.background = args.background;
  config.truth = args.truth;
  StillCollectorOptions& collect = config.collect;
  collect.domain = dds::DomainConfig::FromEnvironment();
  if (args.domain >= 0) collect.domain.domain_id = static_cast<uint32_t>(args.domain);
  if (args.loopback) collect.domain.loopback = true;
  collect.timeout = std::chrono::milliseconds(static_cast<int64_t>(args.timeout_s * 1000));
  collect.discovery = std::chrono::milliseconds(static_cast<int64_t>(args.discovery_s * 1000));
  for (const CameraModel& camera : config.cameras) {
    collect.targets.push_back(
        StillTarget{camera.id, args.at_s >= 0 ? FirstFrameAtOrAfter(camera, args.at_s) : 0});
  }
  const auto run = RunWithProgress(
      "stills", [&](Progress* progress) { return RunStillsStage(config, progress); });
  if (!run) return 130;
  const StillsStageResult& result = *run;
  for (const std::string& warning : result.warnings)
    std::printf("  %s\n", warning.c_str());
  if (args.background) {
    std::printf(
        "stills: %zu of %zu cameras sent the empty scene in %.1f s (kept on the nodes for "
        "their next stills) -> %s/<camera>/background.png\n",
        result.views, config.cameras.size(), result.collection.seconds, args.out.c_str());
    return result.failure.empty() ? 0 : 3;
  }
  std::printf("stills: %zu of %zu cameras answered with a complete still in %.1f s -> %s\n",
              result.views, config.cameras.size(), result.collection.seconds, args.out.c_str());
  if (result.calibration_vs_truth) {
    const CalibrationErrors& e = *result.calibration_vs_truth;
    std::printf(
        "  the calibration in use against the truth: rotation %.3f deg median (%.3f max), "
        "focal length %.2f %% median\n",
        e.median_rotation_deg, e.max_rotation_deg, 100.0 * e.median_focal_rel);
  }
  if (result.stereo) return PrintStereoResult(*result.stereo, (config.output / "stereo").string());
  if (!result.failure.empty()) {
    std::printf("stills: %s\n", result.failure.c_str());
    return 3;
  }
  return 0;
}

}  // namespace

Command AddStillsCommand(CLI::App& app) {
  auto args = std::make_shared<StillsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stills",
      "ask the camera nodes for a still each and collect them as a stills folder (or ask the "
      "live job running in a folder to)");
  cmd->add_option("out", args->out,
                  "output stills folder; without --calib the folder of a running live job "
                  "(`live --serve`), which takes the stills into OUT/stills with the "
                  "calibration it uses and adds the model to its report")
      ->required();
  cmd->add_option("--calib", args->calibration,
                  "calibration.yaml of the cameras to ask (written beside the stills, carried "
                  "over to the stills' resolution)");
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
  cmd->add_flag("--stereo", args->stereo,
                "with --calib: then build the stereo model into <out>/stereo");
  cmd->add_flag("--no-stereo", args->no_stereo,
                "without --calib: the live job collects the stills without building a model");
  cmd->add_flag("--background", args->background,
                "stills of the empty scene: every node keeps its own to segment its later "
                "full-resolution stills against (sources without a background of their own: "
                "V4L2, libcamera); written as OUT/<camera>/background.png (a live job: "
                "OUT/backgrounds)");
  cmd->add_flag("--no-wait", args->no_wait,
                "without --calib: return once asked instead of following the job's answer");
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
