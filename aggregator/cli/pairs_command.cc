// silnet-aggregator pairs: every camera pair's epipolar geometry and time offset.

#include <cstdio>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct PairsArgs {
  std::string input, out, overlays = "ok";
  int max_frames = 0;
  PairwiseArgs pairwise;
};

OverlaySelection ParseOverlays(const std::string& name) {
  if (name == "none") return OverlaySelection::kNone;
  if (name == "all") return OverlaySelection::kAll;
  if (name == "ok") return OverlaySelection::kOk;
  throw InputError("--overlays must be none, ok or all");
}

int RunPairs(const PairsArgs& args) {
  PairsJobConfig config;
  config.input = args.input;
  config.output = args.out;
  config.max_frames = args.max_frames;
  config.mask_video = args.pairwise.mask_video;
  config.frame_video = args.pairwise.frame_video;
  config.options = args.pairwise.Options();
  config.overlays = ParseOverlays(args.overlays);
  const auto run =
      RunWithProgress("pairs", [&](Progress* progress) { return RunPairsJob(config, progress); });
  if (!run) return 130;
  const PairwiseJobResult& result = *run;
  std::printf("pairs: %zu of %zu ok in %.1f s -> %s/pairs.yaml\n", result.ok(), result.pairs.size(),
              result.seconds, args.out.c_str());
  for (const auto& p : result.pairs) {
    std::printf("  %s-%s  %-10s offset %+9.3f +- %.3f  %5zu inliers  %.2f px  %s\n",
                p.camera_i.c_str(), p.camera_j.c_str(), ToString(p.status), p.offset,
                p.offset_sigma, p.inliers, p.residual_rms, p.reason.c_str());
  }
  return 0;
}

}  // namespace

Command AddPairsCommand(CLI::App& app) {
  auto args = std::make_shared<PairsArgs>();
  CLI::App* cmd =
      app.add_subcommand("pairs", "every camera pair's epipolar geometry and time offset");
  cmd->add_option("input", args->input,
                  "session store, node recording, or dataset folder (masks/ or frames/ per camera)")
      ->required();
  cmd->add_option("-o,--out", args->out, "output folder")->required();
  args->pairwise.AddTo(cmd);
  cmd->add_option("--max-frames", args->max_frames, "use at most this many frames (0 = all)");
  cmd->add_option("--overlays", args->overlays, "PNG overlays for none, ok or all pairs")
      ->capture_default_str();
  return {cmd, [args] { return RunPairs(*args); }};
}

}  // namespace silnet::aggregator::cli
