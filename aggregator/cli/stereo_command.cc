// silnet-aggregator stereo: a closed surface model of a still subject from a stills folder and
// its calibration (the baseline graph cut of thesis ch. 5 until the exact silhouette
// constraints of ch. 6 land).

#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/stereo/steps_to_interior.h"
#include "aggregator/stereo/stereo_job.h"
#include "shared/util/check.h"

namespace silnet::aggregator::cli {
namespace {

struct StereoArgs {
  std::string input, calibration, out;
  int still = 0;
  // Each method's own defaults unless given (their terms are not on the same scale).
  double lambda = 0.0, ballooning = 0.0;
  const CLI::Option* lambda_given = nullptr;
  const CLI::Option* ballooning_given = nullptr;
  double finest_cells = AdaptiveTetMeshOptions{}.finest_spacing_footprints;
  const CLI::Option* finest_cells_given = nullptr;
  int silhouette_rounds = StereoGraphCutDefaults().silhouette_rounds;
  int silhouette_join_steps = StereoGraphCutDefaults().silhouette_join_steps;
  int threads = 0;
  std::string method = "uniform";
  std::string constraints = "steps";
  int refine_iterations = SurfaceRefinementOptions{}.iterations;
  bool remove_redundant_pieces = false;
  std::vector<std::string> leave_out;
};

void PrintEvaluation(const char* name, const StereoMeshSummary& mesh) {
  if (!mesh.evaluation) return;
  std::printf("  %s: %s\n", name, mesh.evaluation->Brief().c_str());
  for (const RegionEvaluation& region : mesh.evaluation->regions)
    std::printf("    %s: %s\n", region.name.c_str(), region.Brief().c_str());
}

int RunStereo(const StereoArgs& args) {
  StereoJobConfig config;
  config.input = args.input;
  config.calibration = args.calibration;
  config.output = args.out;
  config.still = args.still;
  config.graph_cut.silhouette_rounds = args.silhouette_rounds;
  config.graph_cut.silhouette_join_steps = args.silhouette_join_steps;
  config.threads = args.threads;
  config.method = args.method == "adaptive" ? StereoMethod::kAdaptive : StereoMethod::kUniform;
  const bool adaptive = config.method == StereoMethod::kAdaptive;
  if (args.lambda_given->count() > 0)
    (adaptive ? config.adaptive.cut.lambda : config.graph_cut.lambda) = args.lambda;
  if (args.ballooning_given->count() > 0)
    (adaptive ? config.adaptive.cut.ballooning : config.graph_cut.ballooning) = args.ballooning;
  config.constraints =
      args.constraints == "exact" ? SilhouetteConstraints::kExact : SilhouetteConstraints::kSteps;
  if (adaptive && config.constraints == SilhouetteConstraints::kExact)
    throw InputError(
        "--silhouette-constraints exact sets the uniform method's cut: use it with --method "
        "uniform");
  if (args.finest_cells_given->count() > 0) {
    if (!adaptive)
      throw InputError("--finest-cells sets the adaptive mesh: use it with --method adaptive");
    config.adaptive.mesh.SetFinestSpacing(args.finest_cells);
  }
  config.refinement.iterations = args.refine_iterations;
  config.remove_redundant_pieces = args.remove_redundant_pieces;
  config.leave_out = args.leave_out;
  const auto run =
      RunWithProgress("stereo", [&](Progress* progress) { return RunStereoJob(config, progress); });
  if (!run) return 130;
  return PrintStereoResult(*run, args.out);
}

}  // namespace

int PrintStereoResult(const StereoJobResult& result, const std::string& out) {
  if (!result.success) {
    std::printf("stereo: no model: %s (%.1f s) -> %s/stereo.yaml\n", result.reason.c_str(),
                result.seconds.total, out.c_str());
    return 3;
  }
  if (result.adaptive) {
    std::printf(
        "stereo (adaptive): %zu views, model %zu triangles, %zu cells (finest %.2f mm); "
        "silhouette pixels >= 1 px inside missed %zu (%zu no consistent model covers), outside "
        "covered %zu (%zu traded for those of other views); %.1f s (hull %.1f, "
        "adaptive stereo %.1f) -> %s/model.ply\n",
        result.views, result.model.triangles, result.adaptive->cells,
        result.adaptive->finest_spacing * 1e3, result.model.MissedInner(),
        result.model.MissedUncoverable(), result.model.CoveredOuter(),
        result.model.CoveredOuterTraded(), result.seconds.total, result.seconds.hull,
        result.seconds.graph_cut, out.c_str());
    PrintEvaluation("model", result.model);
    PrintEvaluation("graph-cut surface", result.cut);
    PrintEvaluation("visual hull", result.hull);
    return 0;
  }
  std::printf(
      "stereo: %zu views, model %zu triangles, lattice %dx%dx%d of %.2f mm, %zu graph nodes; "
      "silhouette pixels >= 1 px inside missed %zu (%zu no consistent model covers), outside "
      "covered %zu (%zu traded for those of other views); %.1f s "
      "(hull %.1f, photo-consistency %.1f, graph cut %.1f) -> %s/model.ply\n",
      result.views, result.model.triangles, result.lattice_dims[0], result.lattice_dims[1],
      result.lattice_dims[2], result.cell_size * 1e3, result.graph_cut.nodes,
      result.model.MissedInner(), result.model.MissedUncoverable(), result.model.CoveredOuter(),
      result.model.CoveredOuterTraded(), result.seconds.total, result.seconds.hull,
      result.seconds.photo_consistency, result.seconds.graph_cut, out.c_str());
  PrintEvaluation("model", result.model);
  PrintEvaluation("graph-cut surface", result.cut);
  PrintEvaluation("visual hull", result.hull);
  return 0;
}

Command AddStereoCommand(CLI::App& app) {
  auto args = std::make_shared<StereoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stereo", "a closed surface model of a still subject from calibrated stills");
  cmd->add_option("input", args->input,
                  "stills folder (<camera>/stills/%06d.png, <camera>/masks/%06d.png), or a "
                  "Middlebury folder (*_par.txt) without --calib")
      ->required();
  cmd->add_option("--calib", args->calibration,
                  "calibration.yaml (or ground_truth.yaml) of a stills folder");
  cmd->add_option("-o,--out", args->out, "output folder")->required();
  cmd->add_option("--still", args->still, "the still (frame number) to reconstruct")
      ->capture_default_str();
  cmd->add_option("--method", args->method,
                  "uniform: votes on a lattice and its graph cut (thesis ch. 5-6); adaptive: the "
                  "adaptive tetrahedral mesh and its dual graph cut (ch. 7; more accurate on "
                  "well-textured subjects, much slower on weakly textured ones: "
                  "docs/PERFORMANCE.md)")
      ->check(CLI::IsMember({"uniform", "adaptive"}))
      ->capture_default_str();
  cmd->add_option("--silhouette-constraints", args->constraints,
                  "uniform method: steps: the cut, then a cell tied inside for every silhouette "
                  "pixel it misses (thesis 7.4.2); exact: the 2-coloured hull's exact "
                  "constraints, Formulation I (6.4-6.6; twice the graph, and where no "
                  "photo-consistency pays for a rim it does not hold it: docs/PERFORMANCE.md)")
      ->check(CLI::IsMember({"steps", "exact"}))
      ->capture_default_str();
  // Values are validated by the job (InputError, exit code 2, with the reason).
  args->lambda_given = cmd->add_option(
      "--lambda", args->lambda,
      fmt::format("uniform: photo-consistency cost exp(-lambda * votes) of the graph cut (> 0, "
                  "default {}); adaptive: cost per unit of face area beside the faces' "
                  "photo-consistency (>= 0, default {})",
                  StereoGraphCutDefaults().lambda, TetGraphCutOptions{}.lambda));
  args->ballooning_given = cmd->add_option(
      "--ballooning", args->ballooning,
      fmt::format("uniform: volume reward per interior cell (>= 0, default {}); adaptive: reward "
                  "per cell no view saw through, x its volume / footprint (>= 0, default {})",
                  StereoGraphCutDefaults().ballooning, TetGraphCutOptions{}.ballooning));
  args->finest_cells_given =
      cmd->add_option("--finest-cells", args->finest_cells,
                      "adaptive: the finest cells' cube side in pixel footprints (tetrahedron "
                      "edges 0.87-1 times it; the base lattice 8 times it). 3 takes the "
                      "Middlebury temple from 4 minutes to 1.6, with coarser detail: "
                      "docs/PERFORMANCE.md")
          ->capture_default_str();
  cmd->add_option("--silhouette-rounds", args->silhouette_rounds,
                  "silhouette steps: re-cuts that cover the silhouette pixels the model misses "
                  "(0 = the plain cut)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--silhouette-join-steps", args->silhouette_join_steps,
                  "uniform: a silhouette step takes the missed pixel's cell nearest the model "
                  "within this many cells and ties the cells between them inside too, so it "
                  "joins the model instead of floating (0 = the ray's most photo-consistent "
                  "cell; fewer pieces, but less accurate where the calibration is off by a "
                  "pixel: docs/PERFORMANCE.md)")
      ->check(CLI::Range(0, StepsToInterior::kMaxSteps))
      ->capture_default_str();
  cmd->add_flag("--remove-redundant-pieces", args->remove_redundant_pieces,
                "remove the model's floating pieces whose silhouette pixels the rest covers too "
                "(a cleaner model, slightly more accurate, slightly less complete)");
  cmd->add_option("--refine-iterations", args->refine_iterations,
                  "local refinement of the cut's surface by texture and silhouette forces "
                  "(thesis 7.4.3; 0 = the graph cut's surface as it is)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--leave-out", args->leave_out,
                  "cameras not to use, by id, comma-separated (e.g. a camera with a bad still)")
      ->delimiter(',');
  cmd->add_option("--threads", args->threads, "threads (0 = all cores)")->capture_default_str();
  return {cmd, [args] { return RunStereo(*args); }};
}

}  // namespace silnet::aggregator::cli
