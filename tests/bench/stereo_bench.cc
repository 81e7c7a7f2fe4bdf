// Stereo job budget (issue: 16 views at 640x480 in <= 2 min all-in on 2 cores, with the memory
// peak): the simulated statue seen by a ring of 16 cameras at 640x480 (`silnet-sim stills`
// defaults), all cores, the job's default options. BM_StereoJob runs the whole job
// (RunStereoJob: load, visual hull, photo-consistency, graph cut with silhouette steps,
// refinement, evaluation, pictures and the output files, into a temporary folder); the others time
// one stage each as the job runs it, their inputs prepared once outside the timing. Every benchmark
// runs one iteration; repeat from the command line with, e.g., OPTIONS =
//   --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// all of them, then the whole job alone:
//   build/tests/bench/silnet_stereo_bench OPTIONS
//   build/tests/bench/silnet_stereo_bench --benchmark_filter=BM_StereoJob OPTIONS
// Memory: peak_MB (BM_StereoJob) is the process's peak resident set (getrusage ru_maxrss), so
// it includes the generation of the stills and every benchmark run before: BM_StereoJob is
// registered first, and the second command runs it alone. Its first repetition gives the
// peak of one job in a fresh process (the generation needs less); later repetitions add what
// the allocator kept from the earlier ones (--benchmark_repetitions=1 gives that figure
// alone). run_peak_MB is the peak resident set during the timed runs only (VmHWM, reset
// through /proc/self/clear_refs; absent where Linux does not allow that); it includes the
// prepared inputs the fixtures hold and memory the allocator kept from earlier work.

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/model_render.h"
#include "aggregator/stereo/photo_consistency.h"
#include "aggregator/stereo/stereo_hull.h"
#include "aggregator/stereo/stereo_job.h"
#include "aggregator/stereo/stereo_truth.h"
#include "aggregator/stereo/stills_folder.h"
#include "aggregator/stereo/surface_refinement.h"
#include "aggregator/stereo/volumetric_graph_cut.h"
#include "shared/io/png_writer.h"
#include "sim/stills_generator.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

// The process's peak resident set since it started, MB: the highest ru_maxrss (kilobytes on
// Linux) read so far, as ResetPeakResidentSet can lower it.
double ProcessPeakMb() {
  static double peak = 0;
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  peak = std::max(peak, static_cast<double>(usage.ru_maxrss) / 1024.0);
  return peak;
}

// Resets the kernel's peak resident set mark of the process to its current resident set,
// after noting the process peak so far (ProcessPeakMb); false where Linux does not allow it
// (then run_peak_MB is not reported).
bool ResetPeakResidentSet() {
  ProcessPeakMb();
  std::ofstream out("/proc/self/clear_refs");
  out << "5" << std::flush;
  return static_cast<bool>(out);
}

// The peak resident set since the last reset (VmHWM of /proc/self/status), MB; 0 if unknown.
double PeakResidentSetMb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0;
}

// Sets counter run_peak_MB to the peak resident set since ResetPeakResidentSet, if that
// succeeded (`was_reset`).
void ReportRunPeak(benchmark::State& state, bool was_reset) {
  if (was_reset) state.counters["run_peak_MB"] = PeakResidentSetMb();
}

// The simulated stills folder (16 cameras, 640x480, with gt_surface.ply), removed at exit.
struct Stills {
  silnet::testing::TempDir dir{"silnet-stereo-bench"};
  std::filesystem::path calibration = dir.path() / "calibration.yaml";

  Stills() {
    sim::StillsOptions options;
    options.overwrite = true;
    sim::GenerateStills(options, dir.path(), nullptr);
  }
};

// Generated on first use.
const Stills& TheStills() {
  static const Stills stills;
  return stills;
}

// The job's load stage: the views and the true surface (empty if the folder has none).
struct Loaded {
  StereoViews views;
  StereoTruth truth;
};

// Loads the stills folder and its gt_surface.ply as RunStereoJob does.
Loaded LoadStage(const Stills& stills) {
  Loaded loaded;
  loaded.views = LoadStillsFolder(stills.dir.path(), stills.calibration);
  loaded.truth = LoadStereoTruth(stills.dir.path()).value_or(StereoTruth());
  return loaded;
}

// Loaded on first use.
const Loaded& TheLoaded() {
  static const Loaded loaded = LoadStage(TheStills());
  return loaded;
}

// The job's visual hull stage: the hull and the silhouettes it came from.
struct Hull {
  CutSilhouettes silhouettes;
  PolyhedralHullResult hull;
};

// The hull of the views whose silhouettes lie inside their image (ComputeStereoHull, all
// cores), as RunStereoJob computes it.
Hull HullStage(const StereoViews& views) {
  Hull hull;
  for (const StereoView& view : views.views) {
    if (TouchesBorder(view.mask)) continue;
    hull.silhouettes.cameras.push_back(view.camera);
    hull.silhouettes.masks.push_back(view.mask);
  }
  std::vector<std::string> warnings;
  hull.hull = ComputeStereoHull(hull.silhouettes, 0, &warnings);
  return hull;
}

// Computed on first use.
const Hull& TheHull() {
  static const Hull hull = HullStage(TheLoaded().views);
  return hull;
}

// The job's photo-consistency (default options, all cores), computed on first use.
const PhotoConsistencyResult& TheVotes() {
  static const PhotoConsistencyResult votes =
      ComputePhotoConsistency(TheLoaded().views.views, TheHull().hull.mesh);
  return votes;
}

// The pixel footprint the job evaluates with: the truth's, else the votes' estimate.
double Footprint() {
  const StereoTruth& truth = TheLoaded().truth;
  return truth.footprint > 0 ? truth.footprint : TheVotes().stats.footprint;
}

// The job's graph cut (StereoGraphCutDefaults, silhouette steps on the hull's silhouettes).
VolumetricGraphCutResult CutStage() {
  return VolumetricGraphCut(TheVotes().volume, TheHull().hull.mesh, StereoGraphCutDefaults(),
                            &TheHull().silhouettes);
}

// Computed on first use.
const VolumetricGraphCutResult& TheCut() {
  static const VolumetricGraphCutResult cut = CutStage();
  return cut;
}

// Why the inputs of a stage are unusable, empty if they are fine (each fixture up to `stage`).
std::string FixtureProblem(const std::string& stage) {
  if (TheLoaded().truth.points.empty()) return "no gt_surface.ply";
  if (stage == "load") return "";
  if (!TheHull().hull.success) return fmt::format("visual hull: {}", TheHull().hull.reason);
  if (stage == "hull") return "";
  if (!TheVotes().success) return fmt::format("photo-consistency: {}", TheVotes().reason);
  if (stage == "photo") return "";
  if (!TheCut().success) return fmt::format("graph cut: {}", TheCut().reason);
  return "";
}

// The job's evaluation stage: silhouette consistency and the measures against the truth of
// hull and model, over the whole surface and over its regions (stereo_truth.h).
struct Evaluation {
  std::vector<SilhouetteConsistency> hull_views, model_views;
  ModelEvaluation hull, model;
};

// Evaluates the hull and the model as RunStereoJob does.
Evaluation EvaluationStage(const TriangleMesh& hull, const TriangleMesh& model) {
  const Loaded& loaded = TheLoaded();
  Evaluation evaluation;
  evaluation.hull_views = MeasureSilhouetteConsistency(hull, loaded.views.views);
  evaluation.model_views = MeasureSilhouetteConsistency(model, loaded.views.views);
  StereoTruthEvaluation measured =
      EvaluateAgainstTruth(hull, model, loaded.truth, Footprint(), loaded.views.views);
  evaluation.hull = std::move(measured.hull);
  evaluation.model = std::move(measured.model);
  return evaluation;
}

// Silhouette pixels at least 1 px inside the outline that the views' model misses, summed.
double MissedInner(const std::vector<SilhouetteConsistency>& views) {
  size_t missed = 0;
  for (const SilhouetteConsistency& view : views)
    missed += view.missed_inner;
  return static_cast<double>(missed);
}

// The whole job with its default settings, writing into a temporary folder; seconds per stage
// from its result (refine_s: the cut's surface refined, redundant pieces removed if asked;
// writing_s: hull.ply, model.ply, stereo.yaml and report.html).
void BM_StereoJob(benchmark::State& state) {
  const Stills& stills = TheStills();
  const silnet::testing::TempDir output("silnet-stereo-bench-out");
  StereoJobConfig config;
  config.input = stills.dir.path();
  config.calibration = stills.calibration;
  config.output = output.path();
  const bool reset = ResetPeakResidentSet();
  StereoJobResult result;
  for (auto _ : state) {
    result = RunStereoJob(config, nullptr);
    if (!result.success) {
      state.SkipWithError(result.reason.c_str());
      break;
    }
  }
  if (!result.success) return;
  ReportRunPeak(state, reset);
  state.counters["peak_MB"] = ProcessPeakMb();
  const StereoStageTimes& s = result.seconds;
  state.counters["views"] = static_cast<double>(result.views);
  state.counters["load_s"] = s.load;
  state.counters["hull_s"] = s.hull;
  state.counters["photo_s"] = s.photo_consistency;
  state.counters["cut_s"] = s.graph_cut;
  state.counters["refine_s"] = s.refinement;
  state.counters["eval_s"] = s.evaluation;
  state.counters["pictures_s"] = s.pictures;
  state.counters["writing_s"] = s.total - s.load - s.hull - s.photo_consistency - s.graph_cut -
                                s.refinement - s.evaluation - s.pictures;
  state.counters["total_s"] = s.total;
}
BENCHMARK(BM_StereoJob)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The whole job with `--method adaptive` (thesis ch. 7), otherwise default settings: argument 0
// on the simulated 16-camera ring, 1 on the Middlebury temple ring (../shared/data; an error
// where it is absent). Seconds per stage of the adaptive stereo, its cells, the peak resident
// set during the run. The temple takes minutes: run it alone, e.g.
//   build/tests/bench/silnet_stereo_bench --benchmark_filter='BM_AdaptiveStereoJob/1'
void BM_AdaptiveStereoJob(benchmark::State& state) {
  const silnet::testing::TempDir output("silnet-stereo-bench-out");
  StereoJobConfig config;
  if (state.range(0) == 0) {
    config.input = TheStills().dir.path();
    config.calibration = TheStills().calibration;
  } else {
    config.input = std::filesystem::path(SILNET_SHARED_DATA_DIR) / "middlebury-templeSparseRing";
    if (!std::filesystem::exists(config.input)) {
      state.SkipWithError("no ../shared/data/middlebury-templeSparseRing");
      return;
    }
  }
  config.output = output.path();
  config.method = StereoMethod::kAdaptive;
  const bool reset = ResetPeakResidentSet();
  StereoJobResult result;
  for (auto _ : state) {
    result = RunStereoJob(config, nullptr);
    if (!result.success || !result.adaptive) {
      state.SkipWithError(result.reason.c_str());
      return;
    }
  }
  ReportRunPeak(state, reset);
  const AdaptiveStereoStats& a = *result.adaptive;
  state.counters["cells"] = static_cast<double>(a.cells);
  state.counters["mesh_s"] = a.seconds_mesh;
  state.counters["labels_s"] = a.seconds_labels;
  state.counters["cut_s"] = a.seconds_cut;
  state.counters["silhouettes_s"] = a.seconds_silhouettes;
  state.counters["surface_s"] = a.seconds_surface;
  state.counters["total_s"] = result.seconds.total;
}
BENCHMARK(BM_AdaptiveStereoJob)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

// Loading the stills folder (undistorted views, masks) and gt_surface.ply.
void BM_LoadStills16Views(benchmark::State& state) {
  const Stills& stills = TheStills();
  const bool reset = ResetPeakResidentSet();
  size_t views = 0;
  for (auto _ : state) {
    const Loaded loaded = LoadStage(stills);
    views = loaded.views.views.size();
    benchmark::DoNotOptimize(loaded.truth.points.data());
  }
  ReportRunPeak(state, reset);
  state.counters["views"] = static_cast<double>(views);
}
BENCHMARK(BM_LoadStills16Views)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The exact polyhedral hull of the 16 silhouettes.
void BM_PolyhedralHull16Views(benchmark::State& state) {
  const std::string problem = FixtureProblem("load");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const StereoViews& views = TheLoaded().views;
  const bool reset = ResetPeakResidentSet();
  Hull hull;
  for (auto _ : state) {
    hull = HullStage(views);
    benchmark::DoNotOptimize(hull.hull.mesh.triangles.data());
  }
  ReportRunPeak(state, reset);
  state.counters["views"] = static_cast<double>(hull.silhouettes.cameras.size());
  state.counters["cone_faces"] = static_cast<double>(hull.hull.stats.cone_faces);
  state.counters["triangles"] = static_cast<double>(hull.hull.mesh.triangles.size());
}
BENCHMARK(BM_PolyhedralHull16Views)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// Photo-consistency (thesis 6.8.1) with every (Arg 1) or every second (Arg 2) pixel.
void BM_PhotoConsistency16Views(benchmark::State& state) {
  const std::string problem = FixtureProblem("hull");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const StereoViews& views = TheLoaded().views;
  const TriangleMesh& hull = TheHull().hull.mesh;
  PhotoConsistencyOptions options;
  options.pixel_step = static_cast<int>(state.range(0));
  const bool reset = ResetPeakResidentSet();
  PhotoConsistencyStats stats;
  for (auto _ : state) {
    const PhotoConsistencyResult result = ComputePhotoConsistency(views.views, hull, options);
    stats = result.stats;
    benchmark::DoNotOptimize(result.volume.votes.data());
  }
  ReportRunPeak(state, reset);
  state.counters["pixels"] = static_cast<double>(stats.reference_pixels);
  state.counters["matches"] = static_cast<double>(stats.matches);
  state.counters["votes"] = static_cast<double>(stats.votes_in_hull);
  state.counters["matching_s"] = stats.seconds_matching;
}
BENCHMARK(BM_PhotoConsistency16Views)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

// The graph cut with the job's defaults, silhouette steps included. missed_final: inner
// silhouette pixels the final model misses over all views (stereo.yaml's
// missed_inner_pixels), measured after the timing.
void BM_GraphCutWithSilhouetteSteps(benchmark::State& state) {
  const std::string problem = FixtureProblem("photo");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const bool reset = ResetPeakResidentSet();
  VolumetricGraphCutResult cut;
  for (auto _ : state) {
    cut = CutStage();
    if (!cut.success) {
      state.SkipWithError(cut.reason.c_str());
      break;
    }
  }
  if (!cut.success) return;
  ReportRunPeak(state, reset);
  const VolumetricGraphCutStats& s = cut.stats;
  state.counters["nodes"] = static_cast<double>(s.nodes);
  state.counters["rounds"] = s.silhouette_rounds;
  state.counters["forced"] = static_cast<double>(s.forced_cells);
  state.counters["missed_first"] =
      s.missed_pixels_per_round.empty() ? 0.0 : static_cast<double>(s.missed_pixels_per_round[0]);
  state.counters["missed_final"] =
      MissedInner(MeasureSilhouetteConsistency(cut.surface, TheLoaded().views.views));
  state.counters["build_s"] = s.seconds_build;
  state.counters["max_flow_s"] = s.seconds_max_flow;
  state.counters["silhouette_s"] = s.seconds_silhouette_step;
  state.counters["graph_MB"] = static_cast<double>(s.graph_bytes) / 1e6;
}
BENCHMARK(BM_GraphCutWithSilhouetteSteps)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The local refinement (thesis 7.4.3) of the cut's surface with the job's defaults, the patch
// scorer built outside the timing. accuracy_fp: the refined model's 90 % accuracy against
// gt_surface.ply, cut_accuracy_fp the cut's, both measured after the timing.
void BM_Refinement16Views(benchmark::State& state) {
  const std::string problem = FixtureProblem("cut");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const Loaded& loaded = TheLoaded();
  const TriangleMesh& cut = TheCut().surface;
  const PatchScorer scorer(loaded.views.views, PatchOptions{});
  SurfaceRefinementOptions options;
  options.threads = StereoJobConfig{}.threads;
  const bool reset = ResetPeakResidentSet();
  TriangleMesh refined;
  SurfaceRefinementStats stats;
  for (auto _ : state) {
    refined = RefineSurface(cut, loaded.views.views, scorer, Footprint(), options, &stats);
  }
  ReportRunPeak(state, reset);
  const ModelEvaluationOptions evaluation = StereoEvaluationOptions(loaded.truth, Footprint());
  state.counters["vertices"] = static_cast<double>(stats.vertices);
  state.counters["restored"] = static_cast<double>(stats.restored);
  state.counters["missed_final"] =
      MissedInner(MeasureSilhouetteConsistency(refined, loaded.views.views));
  state.counters["accuracy_fp"] =
      EvaluateModel(refined, loaded.truth.points, loaded.truth.normals, evaluation)
          .accuracy_footprints;
  state.counters["cut_accuracy_fp"] =
      EvaluateModel(cut, loaded.truth.points, loaded.truth.normals, evaluation).accuracy_footprints;
}
BENCHMARK(BM_Refinement16Views)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The evaluation stage: silhouette consistency in the 16 views and accuracy and completeness
// against gt_surface.ply, of the hull and the model.
void BM_Evaluation16Views(benchmark::State& state) {
  const std::string problem = FixtureProblem("cut");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const TriangleMesh& hull = TheHull().hull.mesh;
  const TriangleMesh& model = TheCut().surface;
  const bool reset = ResetPeakResidentSet();
  Evaluation evaluation;
  for (auto _ : state) {
    evaluation = EvaluationStage(hull, model);
  }
  ReportRunPeak(state, reset);
  state.counters["missed_inner"] = MissedInner(evaluation.model_views);
  state.counters["accuracy_mm"] = evaluation.model.accuracy_m * 1e3;
  if (evaluation.model.completeness.size() > 1)
    state.counters["complete_2fp"] = evaluation.model.completeness[1].fraction;
}
BENCHMARK(BM_Evaluation16Views)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The pictures stage: photo, shaded model and silhouette comparison per view, as PNG files.
void BM_ViewPictures16Views(benchmark::State& state) {
  const std::string problem = FixtureProblem("cut");
  if (!problem.empty()) {
    state.SkipWithError(problem.c_str());
    return;
  }
  const StereoViews& views = TheLoaded().views;
  const TriangleMesh& model = TheCut().surface;
  const silnet::testing::TempDir output("silnet-stereo-bench-pictures");
  const bool reset = ResetPeakResidentSet();
  size_t bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    for (const StereoView& view : views.views) {
      bytes += WritePngFast(output.path() / fmt::format("{}.png", view.camera.id),
                            ViewComparisonPanel(view, model, kViewPicturePanelWidth));
    }
  }
  ReportRunPeak(state, reset);
  state.counters["MB_written"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_ViewPictures16Views)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace silnet::aggregator

BENCHMARK_MAIN();
