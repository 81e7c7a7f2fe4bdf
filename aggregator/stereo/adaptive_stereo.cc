#include "aggregator/stereo/adaptive_stereo.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/tet_point_locator.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Raises the cut's ballooning while its surface misses more than the options' share of the
// inner silhouette pixels of `masks` (one per camera); records the shares and the final factor.
void RaiseBallooningWhileMissing(TetGraphCut* cut, const std::vector<CameraModel>& cameras,
                                 const std::vector<cv::Mat>& masks,
                                 const AdaptiveStereoOptions& options, AdaptiveStereoStats* stats) {
  for (int raises = 0;; ++raises) {
    const double share =
        MissedInnerShare(cut->Surface(), cameras, masks, options.silhouettes.margin_px);
    stats->missed_share.push_back(share);
    if (share <= options.max_missed_share || raises == options.max_ballooning_raises) break;
    const size_t gained = cut->RaiseBallooning(options.ballooning_raise);
    spdlog::info(
        "adaptive stereo: the cut misses {:.1f} % of the inner silhouette pixels; "
        "ballooning x{:.2f}: {} cells gained",
        100 * share, cut->ballooning_factor(), gained);
  }
  stats->ballooning_factor = cut->ballooning_factor();
}

}  // namespace

bool AdaptiveStereoOptions::IsValid(std::string* reason) const {
  std::string why;
  if (!mesh.IsValid(&why)) {
    if (reason) *reason = "mesh: " + why;
    return false;
  }
  if (!cut.IsValid(&why)) {
    if (reason) *reason = "graph cut: " + why;
    return false;
  }
  if (!(max_missed_share >= 0 && max_missed_share <= 1) || !(ballooning_raise >= 1) ||
      max_ballooning_raises < 0) {
    if (reason)
      *reason =
          "ballooning raise: the missed share must lie in [0, 1], the factor be >= 1 and "
          "the raises >= 0";
    return false;
  }
  return true;
}

AdaptiveStereoResult RunAdaptiveStereo(const std::vector<StereoView>& views,
                                       const TriangleMesh& hull, double footprint,
                                       const AdaptiveStereoOptions& options, Progress* progress) {
  SILNET_CHECK(footprint > 0);
  AdaptiveStereoResult result;
  AdaptiveStereoStats& stats = result.stats;
  if (hull.triangles.empty()) {
    result.reason = "the visual hull is empty";
    return result;
  }
  WorldBox box;
  for (const Eigen::Vector3f& v : hull.vertices)
    box.extend(v.cast<double>());

  // True (with the reason set) when the run was cancelled; else advances the progress.
  const auto cancelled = [&]() {
    if (progress && progress->cancelled()) {
      result.reason = "cancelled";
      return true;
    }
    if (progress) progress->Advance();
    return false;
  };
  Clock::time_point start = Clock::now();
  AdaptiveTetMeshOptions mesh_options = options.mesh;
  mesh_options.threads = options.threads;
  const AdaptiveTetMesh adaptive =
      BuildAdaptiveTetMesh(views, box, footprint, mesh_options, progress);
  if (progress) progress->Restart("adaptive stereo: labels, cut, silhouettes, surface", 4);
  if (progress && progress->cancelled()) {
    result.reason = "cancelled";
    return result;
  }
  const ConformingTetMesh conforming = adaptive.mesh.Conform();
  const TetMesh& mesh = conforming.mesh;
  std::vector<int> levels;
  levels.reserve(conforming.leaf.size());
  for (int32_t leaf : conforming.leaf)
    levels.push_back(adaptive.mesh.Level(leaf));
  stats.levels = adaptive.levels;
  stats.cells = mesh.tetrahedra.size();
  stats.quasi_dense_points = adaptive.points.size();
  stats.finest_spacing = adaptive.levels.back().spacing;
  stats.seconds_mesh = SecondsSince(start);

  start = Clock::now();
  const PatchScorer scorer(views, options.mesh.patch);
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  for (const StereoView& view : views) {
    cameras.push_back(view.camera);
    masks.push_back(view.mask);
  }
  CellLabelOptions label_options = options.labels;
  label_options.ray_step = stats.finest_spacing / 2;
  label_options.ray_start = 2 * stats.finest_spacing;
  label_options.min_chord = stats.finest_spacing / 4;
  label_options.threads = options.threads;
  std::vector<uint32_t> votes;
  std::vector<CellFace> faces = SortedCellFaces(mesh);
  const std::vector<CellLabel> labels =
      LabelCells(mesh, faces, levels, adaptive.levels.back().level, scorer, cameras,
                 adaptive.points, label_options, &stats.labels, &votes, progress);
  stats.seconds_labels = SecondsSince(start);
  if (cancelled()) return result;

  start = Clock::now();
  TetGraphCutOptions cut_options = options.cut;
  cut_options.threads = options.threads;
  TetGraphCut cut(mesh, std::move(faces), labels, votes, scorer, footprint, cut_options, progress);
  stats.links = cut.links();
  stats.faces_scored = cut.faces_scored();
  stats.seconds_max_flow = cut.seconds_max_flow();
  if (!cut.Cancelled()) RaiseBallooningWhileMissing(&cut, cameras, masks, options, &stats);
  stats.seconds_cut = SecondsSince(start);
  if (cancelled()) return result;

  start = Clock::now();
  const TetPointLocator locator(mesh, 2 * stats.finest_spacing);
  TetSilhouetteOptions silhouette_options = options.silhouettes;
  silhouette_options.ray_step = stats.finest_spacing / 2;
  const TetSilhouetteStats step =
      EnforceSilhouettesOnTets(&cut, mesh, labels, locator, views, silhouette_options);
  stats.missed = step.missed;
  stats.covered = step.covered;
  stats.forced = step.forced;
  stats.forced_out = step.forced_out;
  stats.seconds_silhouettes = SecondsSince(start);
  if (cancelled()) return result;

  start = Clock::now();
  TetSurfaceOptions surface_options = options.surface;
  surface_options.max_vertex_shift = stats.finest_spacing / 2;
  // The pinch repair keeps out of cells outside the hull or made exterior by the silhouettes.
  std::vector<uint8_t> avoid(labels.size(), 0);
  for (size_t t = 0; t < labels.size(); ++t)
    avoid[t] = labels[t] == CellLabel::kExterior || cut.ForcedSide()[t] == 2 ? 1 : 0;
  result.surface = ExtractTetSurface(mesh, cut.Faces(), cut.Interior(), surface_options,
                                     cut.Forced(), avoid, &stats.repaired);
  stats.seconds_surface = SecondsSince(start);
  if (progress) progress->Advance();
  spdlog::info(
      "adaptive stereo: {} cells ({} levels), {} quasi-dense points, {} faces scored; "
      "{} cells forced inside and {} outside by the silhouettes, {} added for a manifold "
      "surface; {} triangles; "
      "mesh {:.1f} s, labels {:.1f} s, cut {:.1f} s (max-flow {:.1f} s), silhouettes {:.1f} s, "
      "surface {:.1f} s",
      stats.cells, stats.levels.size(), stats.quasi_dense_points, stats.faces_scored, stats.forced,
      stats.forced_out, stats.repaired, result.surface.triangles.size(), stats.seconds_mesh,
      stats.seconds_labels, stats.seconds_cut, stats.seconds_max_flow, stats.seconds_silhouettes,
      stats.seconds_surface);
  if (result.surface.triangles.empty()) {
    result.reason = "the cut is empty";
    return result;
  }
  result.success = true;
  return result;
}

}  // namespace silnet::aggregator
