#include "aggregator/stereo/stereo_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>
#include <sstream>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"
#include "aggregator/report/stereo_report.h"
#include "aggregator/stereo/middlebury_dataset.h"
#include "aggregator/stereo/model_render.h"
#include "aggregator/stereo/stills_folder.h"
#include "aggregator/stereo/t_junction_region.h"
#include "shared/io/png_writer.h"
#include "shared/io/point_cloud_ply.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The value of a "<key> <number>" comment of gt_surface.ply, or 0.
double CommentValue(const OrientedPointCloud& cloud, const std::string& key) {
  for (const std::string& comment : cloud.comments) {
    std::istringstream in(comment);
    std::string name;
    double value = 0;
    if (in >> name >> value && name == key && value > 0) return value;
  }
  return 0;
}

// The true surface of simulated stills, if the folder has one.
struct Truth {
  std::vector<Eigen::Vector3d> points, normals;
  double footprint = 0;  // from its comments, 0 if absent
  double spacing = 0;
};

std::optional<Truth> LoadTruth(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "gt_surface.ply";
  if (!std::filesystem::exists(path)) return std::nullopt;
  const OrientedPointCloud cloud = ReadPointCloudPly(path);
  Truth truth;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    truth.points.push_back(cloud.points[i].cast<double>());
    truth.normals.push_back(cloud.normals[i].cast<double>().normalized());
  }
  truth.footprint = CommentValue(cloud, "footprint_m");
  truth.spacing = CommentValue(cloud, "spacing_m");
  return truth;
}

StereoMeshSummary Summarise(const TriangleMesh& mesh) {
  StereoMeshSummary summary;
  summary.vertices = mesh.vertices.size();
  summary.triangles = mesh.triangles.size();
  summary.closed_manifold = CheckClosedManifold(mesh).closed_manifold;
  summary.volume_m3 = MeshVolume(mesh);
  return summary;
}

ModelEvaluationOptions EvaluationOptions(const Truth& truth, double footprint) {
  ModelEvaluationOptions options;
  options.footprint = footprint;
  options.truth_spacing = truth.spacing;
  return options;
}

// The true points farther than kConcaveRegionFootprints from the hull: where it cannot reach.
SurfaceRegion ConcaveRegion(const TriangleMesh& hull, const Truth& truth, double footprint) {
  std::vector<double> to_hull;
  EvaluateModel(hull, truth.points, truth.normals, EvaluationOptions(truth, footprint), {},
                &to_hull);
  SurfaceRegion region{kConcaveRegion, std::vector<uint8_t>(to_hull.size())};
  for (size_t i = 0; i < to_hull.size(); ++i)
    region.truth[i] = to_hull[i] > kConcaveRegionFootprints * footprint ? 1 : 0;
  return region;
}

// The regions of the truth measured separately: concave (ConcaveRegion) and the surface
// forming the silhouettes' T-junctions (t_junction_region.h) in the views.
std::vector<SurfaceRegion> TruthRegions(const TriangleMesh& hull, const Truth& truth,
                                        double footprint, const std::vector<StereoView>& views) {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  for (const StereoView& view : views) {
    cameras.push_back(view.camera);
    masks.push_back(view.mask);
  }
  return {ConcaveRegion(hull, truth, footprint),
          {kTJunctionRegion, TJunctionRegion(truth.points, truth.normals, cameras, masks)}};
}

// Fills the silhouette figures and the measures against the truth, over all of it and over
// each of `regions`.
void Evaluate(const TriangleMesh& mesh, const std::vector<StereoView>& views,
              const std::optional<Truth>& truth, double footprint,
              const std::vector<SurfaceRegion>& regions, StereoMeshSummary* summary) {
  summary->views = MeasureSilhouetteConsistency(mesh, views);
  if (!truth || !(footprint > 0)) return;
  summary->evaluation = EvaluateModel(mesh, truth->points, truth->normals,
                                      EvaluationOptions(*truth, footprint), regions);
}

bool Cancelled(const Progress* progress, StereoJobResult* result) {
  if (!progress || !progress->cancelled()) return false;
  result->success = false;
  result->reason = "cancelled";
  return true;
}

int AsInt(size_t value) {
  return static_cast<int>(std::min<size_t>(value, static_cast<size_t>(INT32_MAX)));
}

void WriteEvaluation(cv::FileStorage& fs, const ModelEvaluation& e) {
  fs << "{"
     << "accuracy_mm" << e.accuracy_m * 1e3 << "accuracy_footprints" << e.accuracy_footprints
     << "mean_distance_mm" << e.mean_distance_m * 1e3 << "model_samples" << AsInt(e.model_samples)
     << "completeness"
     << "[";
  for (const Completeness& c : e.completeness) {
    fs << "{"
       << "within_footprints" << c.distance_footprints << "within_mm" << c.distance_m * 1e3
       << "fraction" << c.fraction << "}";
  }
  fs << "]";
  if (!e.regions.empty()) {
    fs << "regions"
       << "{";
    for (const RegionEvaluation& r : e.regions) {
      fs << r.name << "{"
         << "truth_points" << AsInt(r.truth_points) << "accuracy_mm" << r.accuracy_m * 1e3
         << "accuracy_footprints" << r.accuracy_footprints << "completeness"
         << "[";
      for (const Completeness& c : r.completeness)
        fs << "{"
           << "within_footprints" << c.distance_footprints << "fraction" << c.fraction << "}";
      fs << "]"
         << "}";
    }
    fs << "}";
  }
  fs << "}";
}

void WriteMesh(cv::FileStorage& fs, const std::string& name, const StereoMeshSummary& m) {
  fs << name << "{"
     << "file" << m.file << "vertices" << AsInt(m.vertices) << "faces" << AsInt(m.triangles)
     << "closed_manifold" << static_cast<int>(m.closed_manifold) << "volume_m3" << m.volume_m3;
  size_t missed = 0, covered = 0;
  for (const SilhouetteConsistency& v : m.views) {
    missed += v.missed_inner;
    covered += v.covered_outer;
  }
  if (!m.views.empty()) {
    fs << "missed_inner_pixels" << AsInt(missed) << "covered_outer_pixels" << AsInt(covered);
  }
  if (m.evaluation) {
    fs << "evaluation";
    WriteEvaluation(fs, *m.evaluation);
  }
  fs << "}";
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

// True if any pixel of the outermost rows or columns of `mask` is silhouette.
bool TouchesBorder(const cv::Mat& mask) {
  return cv::countNonZero(mask.row(0)) > 0 || cv::countNonZero(mask.row(mask.rows - 1)) > 0 ||
         cv::countNonZero(mask.col(0)) > 0 || cv::countNonZero(mask.col(mask.cols - 1)) > 0;
}

// The mean pixel footprint (metres) at the centre of the viewing cones' box, 0 if the cones
// do not bound one.
double FootprintAtConesCentre(const CutSilhouettes& views) {
  const ViewingConeBounds bounds = ComputeViewingConeBounds(views.cameras, views.masks);
  if (!bounds.success) return 0;
  const Eigen::Vector3d centre = bounds.box.center();
  double sum = 0;
  for (const CameraModel& camera : views.cameras)
    sum += std::abs((camera.R * centre + camera.t).z()) / camera.K(0, 0);
  return sum / static_cast<double>(views.cameras.size());
}

// The exact polyhedral hull of `views`, or, when it cannot be closed (symmetric rings such
// as the Middlebury temple's; issue 20), the voxel hull carved at one pixel footprint, with
// a warning saying so.
PolyhedralHullResult ComputeStereoHull(const CutSilhouettes& views, int threads,
                                       std::vector<std::string>* warnings) {
  PolyhedralHullResult exact = ComputePolyhedralHull(views.cameras, views.masks);
  if (exact.success) return exact;
  VoxelHullOptions carve;
  carve.voxel_size = FootprintAtConesCentre(views);
  carve.threads = threads;
  if (!(carve.voxel_size > 0)) return exact;
  const VoxelHullResult voxels = CarveVoxelHull(views.cameras, views.masks, carve);
  if (!voxels.success) {
    exact.reason = fmt::format("{}; voxel carving: {}", exact.reason, voxels.reason);
    return exact;
  }
  warnings->push_back(fmt::format(
      "visual hull: the exact hull failed ({}); carved from voxels of {:.3f} mm instead",
      exact.reason, carve.voxel_size * 1e3));
  spdlog::warn("{}", warnings->back());
  PolyhedralHullResult result;
  result.success = true;
  result.mesh = ExtractBoundaryMesh(voxels.grid);
  return result;
}

// The views of the stills folder with its calibration, or of the Middlebury folder when no
// calibration is given.
StereoViews LoadViews(const StereoJobConfig& config) {
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

}  // namespace

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
  return true;
}

StereoJobResult RunStereoJob(const StereoJobConfig& config, Progress* progress) {
  const Clock::time_point start = Clock::now();
  std::string why;
  if (!config.IsValid(&why)) throw InputError(why);
  StereoJobResult result;
  std::filesystem::create_directories(config.output);
  std::filesystem::remove(config.output / "model.ply");
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
  result.warnings = views.warnings;
  for (const std::string& warning : views.warnings)
    spdlog::warn("{}", warning);
  const std::optional<Truth> truth = LoadTruth(config.input);
  result.seconds.load = SecondsSince(stage);
  if (progress) progress->Advance();
  if (Cancelled(progress, &result)) return finish();

  // Visual hull.
  stage = Clock::now();
  if (progress) progress->Restart("visual hull", 1);
  // A silhouette cut by the image border does not bound the subject: such views are left out
  // of the hull (their photographs still vote).
  CutSilhouettes hull_views;  // the views the hull, and so the constraints, come from
  std::vector<CameraModel>& hull_cameras = hull_views.cameras;
  for (const StereoView& view : views.views) {
    if (TouchesBorder(view.mask)) {
      result.warnings.push_back(view.camera.id +
                                ": the silhouette touches the image border; left out of the hull");
      spdlog::warn("{}", result.warnings.back());
      continue;
    }
    hull_cameras.push_back(view.camera);
    hull_views.masks.push_back(view.mask);
  }
  PolyhedralHullResult hull;
  if (hull_cameras.size() < 2) {
    hull.reason = fmt::format("{} of {} silhouettes lie inside their image, at least 2 needed",
                              hull_cameras.size(), views.views.size());
  } else {
    hull = ComputeStereoHull(hull_views, config.threads, &result.warnings);
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

  // Photo-consistency.
  stage = Clock::now();
  PhotoConsistencyOptions photo = config.photo_consistency;
  photo.threads = config.threads;
  PhotoConsistencyResult votes = ComputePhotoConsistency(views.views, hull.mesh, photo, progress);
  result.seconds.photo_consistency = SecondsSince(stage);
  result.photo_consistency = votes.stats;
  result.lattice_dims = votes.volume.dims;
  result.cell_size = votes.volume.cell_size;
  for (const std::string& warning : votes.warnings)
    result.warnings.push_back("photo-consistency: " + warning);
  if (Cancelled(progress, &result)) return finish();
  if (!votes.success) {
    result.reason = "photo-consistency: " + votes.reason;
    return finish();
  }
  result.footprint = truth && truth->footprint > 0 ? truth->footprint : votes.stats.footprint;

  // Graph cut.
  stage = Clock::now();
  if (progress) progress->Restart("graph cut", 1);
  const VolumetricGraphCutResult cut =
      VolumetricGraphCut(votes.volume, hull.mesh, config.graph_cut, &hull_views);
  spdlog::info("{}", cut.stats.Brief());
  result.seconds.graph_cut = SecondsSince(stage);
  result.graph_cut = cut.stats;
  if (progress) progress->Advance();
  if (Cancelled(progress, &result)) return finish();
  if (!cut.success) {
    result.reason = "graph cut: " + cut.reason;
    return finish();
  }
  if (cut.surface.triangles.empty()) {
    result.reason = "graph cut: the cut surface is empty";
    return finish();
  }
  result.model = Summarise(cut.surface);
  if (!result.model.closed_manifold) {
    result.reason = "graph cut: the surface is not a closed manifold (" +
                    CheckClosedManifold(cut.surface).reason + ")";
    return finish();
  }

  // Evaluation.
  stage = Clock::now();
  if (progress) progress->Restart("evaluation", 2);
  const std::vector<SurfaceRegion> regions =
      truth && result.footprint > 0 ? TruthRegions(hull.mesh, *truth, result.footprint, views.views)
                                    : std::vector<SurfaceRegion>();
  Evaluate(hull.mesh, views.views, truth, result.footprint, regions, &result.hull);
  if (progress) progress->Advance();
  Evaluate(cut.surface, views.views, truth, result.footprint, regions, &result.model);
  if (progress) progress->Advance();
  result.seconds.evaluation = SecondsSince(stage);
  if (Cancelled(progress, &result)) return finish();

  result.model.file = "model.ply";
  WritePlyMesh((config.output / result.model.file).string(), cut.surface);

  // Pictures.
  stage = Clock::now();
  if (progress) progress->Restart("pictures", views.views.size());
  result.view_pictures = WriteViewPictures(config.output, views.views, cut.surface, progress);
  result.seconds.pictures = SecondsSince(stage);
  result.success = true;
  return finish();
}

void WriteStereoSummary(const StereoJobConfig& config, const StereoJobResult& result) {
  const std::filesystem::path path = config.output / "stereo.yaml";
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(fmt::format("cannot write {}", path.string()));
  fs << "format_version" << 1;
  fs << "input" << config.input.string() << "calibration" << config.calibration.string() << "still"
     << config.still;
  fs << "success" << static_cast<int>(result.success);
  if (!result.success) fs << "reason" << result.reason;
  fs << "method"
     << fmt::format("volumetric graph cut (thesis 5.4.1){}",
                    config.graph_cut.silhouette_rounds > 0
                        ? fmt::format(", up to {} silhouette steps (7.4.2)",
                                      config.graph_cut.silhouette_rounds)
                        : "");
  const PhotoConsistencyOptions& photo = config.photo_consistency;
  const VolumetricGraphCutOptions& cut = config.graph_cut;
  fs << "settings"
     << "{"
     << "neighbours" << photo.neighbours.count << "window" << photo.matching.window << "min_ncc"
     << photo.matching.min_ncc << "pixel_step" << photo.pixel_step << "cell_size_footprints"
     << photo.cell_size_footprints << "lambda" << cut.lambda << "ballooning" << cut.ballooning
     << "inner_offset_fraction" << cut.inner_offset_fraction << "threads" << config.threads << "}";
  fs << "views" << AsInt(result.views) << "warnings"
     << "[";
  for (const std::string& warning : result.warnings)
    fs << warning;
  fs << "]";
  fs << "footprint_mm" << result.footprint * 1e3;
  fs << "lattice"
     << "{"
     << "dims"
     << "[" << result.lattice_dims[0] << result.lattice_dims[1] << result.lattice_dims[2] << "]"
     << "cell_size_mm" << result.cell_size * 1e3 << "votes_in_hull"
     << AsInt(result.photo_consistency.votes_in_hull) << "matches"
     << AsInt(result.photo_consistency.matches) << "}";
  const VolumetricGraphCutStats& g = result.graph_cut;
  fs << "graph"
     << "{"
     << "hull_cells" << AsInt(g.hull_cells) << "pocket_cells" << AsInt(g.pocket_cells) << "nodes"
     << AsInt(g.nodes) << "n_links" << AsInt(g.n_links) << "t_link_faces" << AsInt(g.t_link_faces)
     << "interior_cells" << AsInt(g.interior_cells) << "silhouette_rounds" << g.silhouette_rounds
     << "forced_cells" << AsInt(g.forced_cells) << "graph_bytes"
     << static_cast<double>(g.graph_bytes) << "lattice_bytes"
     << static_cast<double>(g.lattice_bytes) << "cut_cost" << g.cut_cost << "}";
  const StereoStageTimes& s = result.seconds;
  fs << "seconds"
     << "{"
     << "load" << s.load << "hull" << s.hull << "photo_consistency" << s.photo_consistency
     << "graph_cut" << s.graph_cut << "evaluation" << s.evaluation << "pictures" << s.pictures
     << "total" << s.total << "}";
  WriteMesh(fs, "hull", result.hull);
  WriteMesh(fs, "model", result.model);
  fs << "silhouettes"
     << "[";
  for (size_t v = 0; v < result.model.views.size(); ++v) {
    const SilhouetteConsistency& m = result.model.views[v];
    fs << "{"
       << "camera" << m.camera_id << "silhouette_pixels" << AsInt(m.silhouette_pixels)
       << "inner_pixels" << AsInt(m.inner_pixels) << "missed_inner" << AsInt(m.missed_inner)
       << "outer_pixels" << AsInt(m.outer_pixels) << "covered_outer" << AsInt(m.covered_outer);
    if (v < result.hull.views.size()) {
      fs << "hull_missed_inner" << AsInt(result.hull.views[v].missed_inner) << "hull_covered_outer"
         << AsInt(result.hull.views[v].covered_outer);
    }
    fs << "}";
  }
  fs << "]";
}

}  // namespace silnet::aggregator
