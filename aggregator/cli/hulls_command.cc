// silnet-aggregator hulls: a visual hull per reference frame from a dataset folder of masks
// or a session store of contours and a calibration, with sub-frame silhouette interpolation.

#include <cstdio>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/hulls/hull_sequence_job.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct HullsArgs {
  std::string input, calibration, frames, out;
  double voxel = 0;
  bool no_interpolation = false, overlays = false, voxels = false;
  int threads = 0;
};

// "A:B" -> [A, B); throws InputError otherwise.
void ParseFrameRange(const std::string& text, int* first, int* last) {
  const size_t colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument(text);
    size_t used_a = 0, used_b = 0;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    *first = std::stoi(a, &used_a);
    *last = std::stoi(b, &used_b);
    if (used_a != a.size() || used_b != b.size()) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw InputError("--frames must be A:B (reference frames A..B-1), got '" + text + "'");
  }
}

int RunHulls(const HullsArgs& args) {
  HullSequenceConfig config;
  config.input = args.input;
  config.calibration = args.calibration;
  config.output = args.out;
  if (args.frames.empty())
    config.every_covered_frame = true;
  else
    ParseFrameRange(args.frames, &config.first_frame, &config.last_frame);
  config.options.voxel_size = args.voxel;
  if (args.no_interpolation) config.options.interpolate = false;
  config.options.overlays = args.overlays;
  config.options.polyhedral = !args.voxels;
  config.options.threads = args.threads;
  const auto run = RunWithProgress(
      "hulls", [&](Progress* progress) { return RunHullSequenceJob(config, progress); });
  if (!run) return 130;
  const HullSequenceResult& result = *run;
  std::printf(
      "hulls: %zu of %zu frames, voxel %.4f m, interpolation %s, mean missed %.3f %%, mean "
      "extra %.3f %%, all closed+manifold %s, %.1f s -> %s/hulls.yaml\n",
      result.Succeeded(), result.frames.size(), result.voxel_size,
      result.interpolated ? "on" : "off", 100 * result.MeanMissed(), 100 * result.MeanSpurious(),
      result.AllClosedManifold() ? "yes" : "no", result.seconds, args.out.c_str());
  for (const HullFrameResult& f : result.frames) {
    if (!f.success) std::printf("  frame %d: no hull: %s\n", f.frame, f.reason.c_str());
  }
  return result.Succeeded() == result.frames.size() ? 0 : 3;
}

}  // namespace

Command AddHullsCommand(CLI::App& app) {
  auto args = std::make_shared<HullsArgs>();
  CLI::App* cmd = app.add_subcommand("hulls", "a visual hull per reference frame from silhouettes");
  cmd->add_option("input", args->input,
                  "dataset folder (<camera>/masks/%06d.png) or session store (contours)")
      ->required();
  cmd->add_option("--calib", args->calibration, "calibration.yaml (or ground_truth.yaml)")
      ->required();
  cmd->add_option("--frames", args->frames,
                  "reference frames A:B (A..B-1) of the camera with time offset 0 (default: "
                  "every frame all cameras' silhouettes cover)");
  cmd->add_option("-o,--out", args->out, "output folder")->required();
  cmd->add_option("--voxel", args->voxel,
                  "voxel edge in metres, when carving (default: 1/200 of the bounds)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-interpolation", args->no_interpolation,
                "use each camera's nearest frame instead of sub-frame silhouettes");
  cmd->add_flag("--overlays", args->overlays, "write reprojection overlays under OUT/overlays/");
  cmd->add_flag("--voxels", args->voxels,
                "carve voxel hulls instead of the exact polyhedral ones (which fall back to "
                "voxels for a frame they cannot close)");
  cmd->add_option("--threads", args->threads, "threads (0 = all cores)")->capture_default_str();
  return {cmd, [args] { return RunHulls(*args); }};
}

}  // namespace silnet::aggregator::cli
