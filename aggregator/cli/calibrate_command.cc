// silnet-aggregator calibrate: pairs -> synchronisation -> calibration in one go, with
// calibration.yaml, a COLMAP export, a report, and optionally the Calibration topic on DDS.

#include <spdlog/spdlog.h>

#include <cstdio>
#include <thread>

#include "aggregator/calibration/calibrate_job.h"
#include "aggregator/calibration/calibration_publisher.h"
#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "shared/dds/domain_config.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct CalibrateArgs {
  std::string input, out, reuse_pairs, intrinsics, ground_truth, distortion = "auto";
  int max_frames = 0;
  PairwiseArgs pairwise;
  bool free_aspect = false, fix_principal_point = false, no_report = false;
  int rematch_rounds = 1, max_rematch_rounds = CalibrationOptions{}.max_rematch_rounds;
  double rig_radius = 1.0, principal_point_sigma = 0.0;
  bool publish = false, loopback = false;
  double linger_s = 10.0;
  int domain = -1;
};

void PrintResult(const CalibrateJobResult& result, const std::string& out) {
  const NetworkCalibration& c = result.calibration;
  std::printf(
      "calibrate: %zu of %zu cameras calibrated, reprojection rms %.3f px (median %.3f), "
      "%zu of %zu pairs ok, %.1f s -> %s/calibration.yaml\n",
      c.PlacedCount(), c.cameras.size(), c.rms_px, c.median_px, result.pairs.ok(),
      result.pairs.pairs.size(), result.seconds, out.c_str());
  for (size_t k = 0; k < c.cameras.size(); ++k) {
    const CameraModel& cam = c.cameras[k];
    const CameraPlacement& p = c.placement[k];
    if (k < c.motion.size() && c.motion[k].frames > 0)
      std::printf("  %-8s motion: %s\n", cam.id.c_str(), c.motion[k].Describe().c_str());
    if (!p.placed) {
      std::printf("  %-8s not calibrated: %s\n", cam.id.c_str(), p.reason.c_str());
      continue;
    }
    std::printf("  %-8s f %8.2f  pp (%7.2f, %7.2f)  k1 %+.4f  offset %+8.3f +- %.3f  %.3f px  %s\n",
                cam.id.c_str(), cam.K(0, 0), cam.K(0, 2), cam.K(1, 2), cam.dist[0], cam.time_offset,
                c.sync.sigmas[k], p.rms_px, p.added_by.c_str());
    const CameraUncertainty& u = p.uncertainty;
    if (u.estimated) {
      std::printf(
          "  %-8s standard deviation: rotation %.3f deg, centre %.3f %% of the rig, focal %.3f "
          "%%, pp %.2f px\n",
          cam.id.c_str(), u.rotation_deg, 100 * u.center_rel, 100 * u.focal_rel, u.principal_px);
    }
  }
  size_t corrected = 0;
  for (const PairCheck& p : c.pairs)
    corrected += p.corrected ? 1 : 0;
  std::printf("  pairwise estimates corrected or supplied by the calibration: %zu\n", corrected);
  if (result.errors) {
    const CalibrationErrors& e = *result.errors;
    std::printf(
        "  against ground truth: focal %.2f %% (max %.2f), rotation %.3f deg (max %.3f), centre "
        "%.3f %% of the rig (max %.3f), offset %.4f frames (max %.4f)\n",
        100 * e.median_focal_rel, 100 * e.max_focal_rel, e.median_rotation_deg, e.max_rotation_deg,
        100 * e.median_center_rel, 100 * e.max_center_rel, e.median_offset_frames,
        e.max_offset_frames);
  }
}

void Publish(const CalibrateArgs& args, const NetworkCalibration& calibration) {
  dds::DomainConfig domain = dds::DomainConfig::FromEnvironment();
  if (args.domain >= 0) domain.domain_id = static_cast<uint32_t>(args.domain);
  if (args.loopback) domain.loopback = true;
  const dds::Participant participant(domain);
  CalibrationPublisher publisher(participant);
  const size_t written = publisher.Publish(calibration, NewCalibrationId());
  spdlog::info("published {} camera calibrations on {}; keeping them available for {} s", written,
               domain.Describe(), args.linger_s);
  const auto until =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(args.linger_s);
  while (!StopRequested() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

int RunCalibrate(const CalibrateArgs& args) {
  CalibrateJobConfig config;
  config.input = args.input;
  config.output = args.out;
  config.pairwise = args.pairwise.Options();
  config.reuse_pairs = args.reuse_pairs;
  config.intrinsics = args.intrinsics;
  config.ground_truth = args.ground_truth;
  config.max_frames = args.max_frames;
  config.mask_video = args.pairwise.mask_video;
  config.frame_video = args.pairwise.frame_video;
  config.report = !args.no_report;
  config.calibration.intrinsics.square_pixels = !args.free_aspect;
  config.calibration.intrinsics.fix_principal_point = args.fix_principal_point;
  config.calibration.intrinsics.principal_point_sigma_px = args.principal_point_sigma;
  ApplyDistortionSetting(args.distortion, &config.calibration);
  config.calibration.rematch_rounds = args.rematch_rounds;
  config.calibration.max_rematch_rounds = std::max(args.max_rematch_rounds, args.rematch_rounds);
  config.calibration.rig_radius = args.rig_radius;
  if (const std::string why = config.calibration.Validate(); !why.empty()) throw InputError(why);
  const auto run = RunWithProgress(
      "calibrate", [&](Progress* progress) { return RunCalibrateJob(config, progress); });
  if (!run) return 130;
  const CalibrateJobResult& result = *run;
  PrintResult(result, args.out);
  if (args.publish && result.calibration.PlacedCount() > 0) Publish(args, result.calibration);
  return result.calibration.PlacedCount() >= 2 ? 0 : 3;
}

}  // namespace

Command AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "pairs, synchronisation and calibration of the whole network in one go");
  cmd->add_option("input", args->input,
                  "session store, node recording, or dataset folder (masks/ or frames/ per camera)")
      ->required();
  cmd->add_option("-o,--out", args->out, "output folder")->required();
  args->pairwise.AddTo(cmd);
  cmd->add_option("--max-frames", args->max_frames, "use at most this many frames (0 = all)");
  cmd->add_option("--pairs", args->reuse_pairs,
                  "reuse the results of an earlier `pairs` run in this folder");
  cmd->add_option("--intrinsics", args->intrinsics,
                  "calibration YAML with trusted K and distortion per camera (known intrinsics)");
  cmd->add_option("--ground-truth", args->ground_truth,
                  "calibration YAML to compare the result with (default: the input's "
                  "ground_truth.yaml, if any)");
  cmd->add_flag("--free-aspect", args->free_aspect, "estimate fx and fy separately");
  cmd->add_flag("--fix-principal-point", args->fix_principal_point,
                "keep the principal point at the image centre");
  cmd->add_option("--principal-point-sigma", args->principal_point_sigma,
                  "prior on the principal point about the image centre, pixels (0 = none); "
                  "steadies rings of cameras that all look at one point")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  AddDistortionOption(cmd, &args->distortion);
  cmd->add_option("--rematch-rounds", args->rematch_rounds,
                  "rounds of frontier re-matching under the calibration, at least (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--max-rematch-rounds", args->max_rematch_rounds,
                  fmt::format("further rounds while the last still turned a camera by {} deg "
                              "or more, up to this many in all",
                              CalibrationOptions{}.rematch_settled_deg))
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--rig-radius", args->rig_radius,
                  "world scale: mean distance of the cameras from their centroid")
      ->capture_default_str();
  cmd->add_flag("--no-report", args->no_report, "skip the HTML report");
  cmd->add_flag("--publish", args->publish, "publish the Calibration topic over DDS");
  cmd->add_option("--linger", args->linger_s, "seconds to keep published calibrations available")
      ->capture_default_str();
  cmd->add_option("--domain", args->domain, "DDS domain id (default: SILNET_DDS_DOMAIN or 0)");
  cmd->add_flag("--loopback", args->loopback, "DDS on 127.0.0.1 only");
  return {cmd, [args] { return RunCalibrate(*args); }};
}

}  // namespace silnet::aggregator::cli
