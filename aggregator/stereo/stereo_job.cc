#include "aggregator/stereo/stereo_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <opencv2/core.hpp>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/mesh_topology.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/report/stereo_report.h"
#include "aggregator/stereo/middlebury_dataset.h"
#include "aggregator/stereo/model_render.h"
#include "aggregator/stereo/stereo_graph.h"
#include "aggregator/stereo/stereo_hull.h"
#include "aggregator/stereo/stereo_truth.h"
#include "aggregator/stereo/stills_folder.h"
#include "shared/io/png_writer.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

StereoMeshSummary Summarise(const TriangleMesh& mesh) {
  StereoMeshSummary summary;
  summary.vertices = mesh.vertices.size();
  summary.triangles = mesh.triangles.size();
  summary.closed_manifold = CheckClosedManifold(mesh).closed_manifold;
  const std::vector<MeshComponent> pieces = MeshComponents(mesh);
  summary.pieces = pieces.size();
  summary.main_genus = pieces.empty() ? 0 : pieces.front().genus;
  summary.volume_m3 = MeshVolume(mesh);
  return summary;
}

bool Cancelled(const Progress* progress, StereoJobResult* result) {
  if (!progress || !progress->cancelled()) return false;
  result->success = false;
  result->reason = "cancelled";
  return true;
}

// Writes views/<camera>.png (ViewComparisonPanel) for every view and returns their paths
// relative to `output`.
std::vector<std::string> WriteViewPictures(const std::filesystem::path& output,
                                           const std::vector<StereoView>& views,
                                           const TriangleMesh& model, Progress* progress) {
  std::filesystem::create_directories(output / "views");
  std::vector<std::string> pictures;
  for (const StereoView& view : views) {
    const std::string file = fmt::format("views/{}.png", view.camera.id);
    WritePngFast(output / file, ViewComparisonPanel(view, model, kViewPicturePanelWidth));
    pictures.push_back(file);
    if (progress) progress->Advance();
  }
  return pictures;
}

// The views of the stills folder with its calibration, or of the Middlebury folder when no
// calibration is given.
StereoViews LoadAllViews(const StereoJobConfig& config) {
  if (!config.calibration.empty()) {
    StillsFolderOptions load;
    load.frame = config.still;
    return LoadStillsFolder(config.input, config.calibration, load);
  }
  if (config.still != 0) throw InputError("a Middlebury folder has one still only (--still 0)");
  try {
    return LoadMiddlebury(config.input);
  } catch (const InputError& e) {
    throw InputError(
        fmt::format("no calibration given (--calib) and {} is not a Middlebury folder either: {}",
                    config.input.string(), e.what()));
  }
}

// The loaded views but those the config leaves out (InputError for a name that is not one of
// them, or fewer than two views left).
StereoViews LoadViews(const StereoJobConfig& config) {
  StereoViews loaded = LoadAllViews(config);
  for (const std::string& id : config.leave_out) {
    const auto it = std::find_if(loaded.views.begin(), loaded.views.end(),
                                 [&id](const StereoView& v) { return v.camera.id == id; });
    if (it == loaded.views.end())
      throw InputError(
          fmt::format("--leave-out {}: no such view among the {} loaded", id, loaded.views.size()));
    loaded.views.erase(it);
    loaded.warnings.push_back(id + ": left out as asked");
  }
  if (loaded.views.size() < 2)
    throw InputError(fmt::format("only {} view(s) left after leaving out {}", loaded.views.size(),
                                 config.leave_out.size()));
  return loaded;
}

// The model by the adaptive tetrahedral stereo (ch. 7) into `surface`; false with the
// reason in `result` on failure or cancellation.
bool AdaptiveModel(const StereoJobConfig& config, const StereoViews& views,
                   const PolyhedralHullResult& hull, const std::optional<StereoTruth>& truth,
                   Progress* progress, StereoJobResult* result, TriangleMesh* surface) {
  const Clock::time_point stage = Clock::now();
  result->footprint =
      truth && truth->footprint > 0 ? truth->footprint : MeanFootprint(views.views, hull.mesh);
  AdaptiveStereoOptions adaptive = config.adaptive;
  adaptive.threads = config.threads;
  AdaptiveStereoResult run =
      RunAdaptiveStereo(views.views, hull.mesh, result->footprint, adaptive, progress);
  result->adaptive = run.stats;
  result->seconds.graph_cut = SecondsSince(stage);
  if (Cancelled(progress, result)) return false;
  if (!run.success) {
    result->reason = "adaptive stereo: " + run.reason;
    return false;
  }
  *surface = std::move(run.surface);
  return true;
}

// The model by votes on a uniform lattice and its graph cut (ch. 5-6) into `surface`; false
// with the reason in `result` on failure or cancellation.
bool UniformModel(const StereoJobConfig& config, const StereoViews& views,
                  const PolyhedralHullResult& hull, const CutSilhouettes& hull_views,
                  const CutSilhouettes& border_views, const std::optional<StereoTruth>& truth,
                  Progress* progress, StereoJobResult* result, TriangleMesh* surface) {
  // Photo-consistency.
  Clock::time_point stage = Clock::now();
  PhotoConsistencyOptions photo = config.photo_consistency;
  photo.threads = config.threads;
  PhotoConsistencyResult votes = ComputePhotoConsistency(views.views, hull.mesh, photo, progress);
  result->seconds.photo_consistency = SecondsSince(stage);
  result->photo_consistency = votes.stats;
  result->lattice_dims = votes.volume.dims;
  result->cell_size = votes.volume.cell_size;
  for (const std::string& warning : votes.warnings)
    result->warnings.push_back("photo-consistency: " + warning);
  if (Cancelled(progress, result)) return false;
  if (!votes.success) {
    result->reason = "photo-consistency: " + votes.reason;
    return false;
  }
  result->footprint = truth && truth->footprint > 0 ? truth->footprint : votes.stats.footprint;

  // Graph cut.
  stage = Clock::now();
  if (progress) progress->Restart("graph cut", 1);
  VoxelGrid hull_cells = HullOnLattice(hull.mesh, votes.volume);
  if (!border_views.cameras.empty()) {
    const BorderCarving carving = CarveByBorderViews(
        border_views, hull_views, config.graph_cut.silhouette_margin_px, &hull_cells);
    spdlog::info(
        "the {} silhouettes the image border cuts carved {} hull cells; {} given back to cover "
        "the other views' silhouettes",
        border_views.cameras.size(), carving.carved, carving.restored);
  }
  CutSilhouettes constraints = hull_views;  // every view's silhouette must be covered
  constraints.cameras.insert(constraints.cameras.end(), border_views.cameras.begin(),
                             border_views.cameras.end());
  constraints.masks.insert(constraints.masks.end(), border_views.masks.begin(),
                           border_views.masks.end());
  VolumetricGraphCutResult cut;
  if (config.constraints == SilhouetteConstraints::kExact) {
    ExactConstraintCutResult exact =
        ExactConstraintCut(votes.volume, hull_cells, hull, hull_views, config.graph_cut, progress);
    cut = std::move(exact.cut);
    result->exact_constraints = exact.exact;
    const HullColouringStats& c = exact.exact.colouring;
    spdlog::info(
        "exact silhouette constraints: {} viewing-edge segments ({} false), {} strip repairs, "
        "{} green vertices, {} hidden-rim labels; surface layer {} cells, {} red, {} blue, {} "
        "clashes; {} twisted cells ({:.1f} s colouring)",
        c.segments, c.false_segments, c.connecting_curves, c.green_vertices, c.hidden_rim,
        exact.exact.layer_cells, exact.exact.red_cells, exact.exact.blue_cells, exact.exact.clashes,
        exact.exact.twisted_cells, exact.exact.seconds_colouring);
  } else {
    cut = VolumetricGraphCut(votes.volume, hull_cells, config.graph_cut, &constraints, progress);
  }
  spdlog::info("{}", cut.stats.Brief());
  result->seconds.graph_cut = SecondsSince(stage);
  result->graph_cut = cut.stats;
  if (progress) progress->Advance();
  if (Cancelled(progress, result)) return false;
  if (!cut.success) {
    result->reason = "graph cut: " + cut.reason;
    return false;
  }
  if (cut.surface.triangles.empty()) {
    result->reason = "graph cut: the cut surface is empty";
    return false;
  }
  *surface = cut.surface;
  return true;
}

// A silhouette figure summed over a mesh's views.
size_t SumOverViews(const std::vector<SilhouetteConsistency>& views,
                    size_t SilhouetteConsistency::*figure) {
  size_t sum = 0;
  for (const SilhouetteConsistency& v : views)
    sum += v.*figure;
  return sum;
}

}  // namespace

size_t StereoMeshSummary::MissedInner() const {
  return SumOverViews(views, &SilhouetteConsistency::missed_inner);
}

size_t StereoMeshSummary::CoveredOuter() const {
  return SumOverViews(views, &SilhouetteConsistency::covered_outer);
}

size_t StereoMeshSummary::MissedUncoverable() const {
  return SumOverViews(views, &SilhouetteConsistency::missed_uncoverable);
}

size_t StereoMeshSummary::CoveredOuterTraded() const {
  return SumOverViews(views, &SilhouetteConsistency::covered_outer_traded);
}

std::string ToString(StereoMethod method) {
  return method == StereoMethod::kAdaptive ? "adaptive" : "uniform";
}

VolumetricGraphCutOptions StereoGraphCutDefaults() {
  VolumetricGraphCutOptions options;
  options.lambda = 3.0;
  options.ballooning = 0.1;
  options.silhouette_rounds = 6;
  return options;
}

bool StereoJobConfig::IsValid(std::string* reason) const {
  if (still < 0) {
    *reason = "the still number must be >= 0";
    return false;
  }
  if (threads < 0) {
    *reason = "threads must be >= 0";
    return false;
  }
  const std::string photo = photo_consistency.Validate();
  if (!photo.empty()) {
    *reason = "photo-consistency: " + photo;
    return false;
  }
  std::string cut;
  if (!graph_cut.IsValid(&cut)) {
    *reason = "graph cut: " + cut;
    return false;
  }
  std::string adaptive_reason;
  if (!adaptive.IsValid(&adaptive_reason)) {
    *reason = "adaptive " + adaptive_reason;
    return false;
  }
  std::string refine;
  if (!refinement.IsValid(&refine)) {
    *reason = "refinement: " + refine;
    return false;
  }
  return true;
}

StereoJobResult RunStereoJob(const StereoJobConfig& config, Progress* progress) {
  const Clock::time_point start = Clock::now();
  std::string why;
  if (!config.IsValid(&why)) throw InputError(why);
  StereoJobResult result;
  std::filesystem::create_directories(config.output);
  std::filesystem::remove(config.output / "model.ply");
  std::filesystem::remove(config.output / "cut.ply");
  std::filesystem::remove_all(config.output / "views");
  const auto finish = [&]() {
    result.seconds.total = SecondsSince(start);
    WriteStereoSummary(config, result);
    WriteStereoReport(config, result);
    if (progress) progress->Finish();
    if (!result.success) spdlog::warn("stereo: no model: {}", result.reason);
    return result;
  };

  // Load.
  Clock::time_point stage = Clock::now();
  if (progress) progress->Restart("load", 1);
  const StereoViews views = LoadViews(config);
  result.views = views.views.size();
  for (const StereoView& view : views.views)
    result.cameras.push_back(view.camera);
  result.warnings = views.warnings;
  for (const std::string& warning : views.warnings)
    spdlog::warn("{}", warning);
  const std::optional<StereoTruth> truth = LoadStereoTruth(config.input);
  result.seconds.load = SecondsSince(stage);
  if (progress) progress->Advance();
  if (Cancelled(progress, &result)) return finish();

  // Visual hull.
  stage = Clock::now();
  if (progress) progress->Restart("visual hull", 1);
  // A silhouette cut by the image border does not bound the subject outside the image: such
  // views are left out of the exact hull and carve it on the lattice inside their images.
  CutSilhouettes hull_views;    // the views the exact hull comes from
  CutSilhouettes border_views;  // the others
  std::vector<CameraModel>& hull_cameras = hull_views.cameras;
  for (const StereoView& view : views.views) {
    CutSilhouettes& into = TouchesBorder(view.mask) ? border_views : hull_views;
    into.cameras.push_back(view.camera);
    into.masks.push_back(view.mask);
  }
  for (const CameraModel& camera : border_views.cameras) {
    result.warnings.push_back(camera.id +
                              ": the silhouette touches the image border; left out of the exact "
                              "hull, it carves the hull inside its image");
    spdlog::warn("{}", result.warnings.back());
  }
  PolyhedralHullResult hull;
  if (hull_cameras.size() < 2) {
    hull.reason = fmt::format("{} of {} silhouettes lie inside their image, at least 2 needed",
                              hull_cameras.size(), views.views.size());
  } else {
    hull = ComputeStereoHull(hull_views, config.threads, &result.warnings,
                             config.method == StereoMethod::kUniform &&
                                 config.constraints == SilhouetteConstraints::kExact);
  }
  result.seconds.hull = SecondsSince(stage);
  if (!hull.success || hull.mesh.triangles.empty()) {
    result.reason = "visual hull: " + (hull.success ? std::string("empty") : hull.reason);
    return finish();
  }
  result.hull = Summarise(hull.mesh);
  result.hull.file = "hull.ply";
  WritePlyMesh((config.output / result.hull.file).string(), hull.mesh);
  if (progress) progress->Advance();
  if (Cancelled(progress, &result)) return finish();

  TriangleMesh model_surface;
  const bool built =
      config.method == StereoMethod::kAdaptive
          ? AdaptiveModel(config, views, hull, truth, progress, &result, &model_surface)
          : UniformModel(config, views, hull, hull_views, border_views, truth, progress, &result,
                         &model_surface);
  if (!built) return finish();
  result.model = Summarise(model_surface);
  if (!result.model.closed_manifold) {
    result.reason = "graph cut: the surface is not a closed manifold (" +
                    CheckClosedManifold(model_surface).reason + ")";
    return finish();
  }

  // Refinement.
  TriangleMesh cut_surface;  // stays empty without refinement
  if (config.refinement.iterations > 0) {
    stage = Clock::now();
    SurfaceRefinementOptions refine = config.refinement;
    refine.threads = config.threads;
    const PatchScorer scorer(views.views, config.refinement.patch);
    SurfaceRefinementStats refined_stats;
    TriangleMesh refined = RefineSurface(model_surface, views.views, scorer, result.footprint,
                                         refine, &refined_stats, progress);
    result.refinement = refined_stats;
    if (const PixelReachStats& reach = refined_stats.reach; reach.coverable_before > 0) {
      spdlog::info(
          "refinement: {} of the {} missed silhouette pixels a consistent model covers reached "
          "by moving {} vertices ({} moves undone, {:.1f} s)",
          reach.missed_before - reach.missed_after, reach.coverable_before, reach.moved,
          reach.undone, reach.seconds);
    }
    result.seconds.refinement = SecondsSince(stage);
    if (Cancelled(progress, &result)) return finish();
    result.cut = result.model;
    result.cut.file = "cut.ply";
    cut_surface = std::move(model_surface);
    model_surface = std::move(refined);
    result.model = Summarise(model_surface);
    if (!result.model.closed_manifold) {
      result.reason = "refinement: the surface is not a closed manifold (" +
                      CheckClosedManifold(model_surface).reason + ")";
      return finish();
    }
  }

  // Floating pieces no silhouette pixel needs.
  stage = Clock::now();
  if (config.remove_redundant_pieces) {
    const RedundantPieceStats& pieces = result.redundant_pieces.emplace(
        RemoveRedundantPieces(views.views, &model_surface, kSilhouetteMarginPx, config.threads));
    if (pieces.removed > 0) {
      spdlog::info(
          "model: {} of its {} pieces removed ({} triangles): every silhouette pixel they "
          "cover is covered by the rest ({:.1f} s)",
          pieces.removed, pieces.pieces_before, pieces.triangles_removed, pieces.seconds);
      result.model = Summarise(model_surface);
    }
  }
  result.seconds.refinement += SecondsSince(stage);

  // Evaluation.
  stage = Clock::now();
  if (progress) progress->Restart("evaluation", 2);
  result.hull.views =
      MeasureSilhouetteConsistency(hull.mesh, views.views, kSilhouetteMarginPx, config.threads);
  result.model.views =
      MeasureSilhouetteConsistency(model_surface, views.views, kSilhouetteMarginPx, config.threads);
  if (!cut_surface.triangles.empty()) {
    result.cut.views =
        MeasureSilhouetteConsistency(cut_surface, views.views, kSilhouetteMarginPx, config.threads);
  }
  if (progress) progress->Advance();
  if (truth && result.footprint > 0) {
    StereoTruthEvaluation measured = EvaluateAgainstTruth(
        hull.mesh, model_surface, *truth, result.footprint, views.views,
        cut_surface.triangles.empty() ? nullptr : &cut_surface, config.threads);
    result.hull.evaluation = std::move(measured.hull);
    result.model.evaluation = std::move(measured.model);
    result.cut.evaluation = std::move(measured.cut);
  }
  if (progress) progress->Advance();
  result.seconds.evaluation = SecondsSince(stage);
  if (Cancelled(progress, &result)) return finish();

  result.model.file = "model.ply";
  WritePlyMesh((config.output / result.model.file).string(), model_surface);
  if (!cut_surface.triangles.empty())
    WritePlyMesh((config.output / result.cut.file).string(), cut_surface);

  // Pictures.
  stage = Clock::now();
  if (progress) progress->Restart("pictures", views.views.size());
  result.view_pictures = WriteViewPictures(config.output, views.views, model_surface, progress);
  result.seconds.pictures = SecondsSince(stage);
  result.success = true;
  return finish();
}

}  // namespace silnet::aggregator
