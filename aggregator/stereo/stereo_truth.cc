#include "aggregator/stereo/stereo_truth.h"

#include <sstream>
#include <string>

#include "aggregator/stereo/t_junction_region.h"
#include "shared/io/point_cloud_ply.h"

namespace silnet::aggregator {
namespace {

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

// The true points farther than kConcaveRegionFootprints from the hull (`truth_to_hull`, as
// ModelDistances gives it): where it cannot reach.
SurfaceRegion ConcaveRegion(const std::vector<double>& truth_to_hull, double footprint) {
  SurfaceRegion region{kConcaveRegion, std::vector<uint8_t>(truth_to_hull.size())};
  for (size_t i = 0; i < truth_to_hull.size(); ++i)
    region.truth[i] = truth_to_hull[i] > kConcaveRegionFootprints * footprint ? 1 : 0;
  return region;
}

// The surface forming the silhouettes' T-junctions in `views` (t_junction_region.h).
SurfaceRegion TJunctions(const StereoTruth& truth, const std::vector<StereoView>& views) {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  for (const StereoView& view : views) {
    cameras.push_back(view.camera);
    masks.push_back(view.mask);
  }
  return {kTJunctionRegion, TJunctionRegion(truth.points, truth.normals, cameras, masks)};
}

}  // namespace

std::optional<StereoTruth> LoadStereoTruth(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "gt_surface.ply";
  if (!std::filesystem::exists(path)) return std::nullopt;
  const OrientedPointCloud cloud = ReadPointCloudPly(path);
  StereoTruth truth;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    truth.points.push_back(cloud.points[i].cast<double>());
    truth.normals.push_back(cloud.normals[i].cast<double>().normalized());
  }
  truth.footprint = CommentValue(cloud, "footprint_m");
  truth.spacing = CommentValue(cloud, "spacing_m");
  return truth;
}

ModelEvaluationOptions StereoEvaluationOptions(const StereoTruth& truth, double footprint,
                                               int threads) {
  ModelEvaluationOptions options;
  options.footprint = footprint;
  options.truth_spacing = truth.spacing;
  options.threads = threads;
  return options;
}

StereoTruthEvaluation EvaluateAgainstTruth(const TriangleMesh& hull, const TriangleMesh& model,
                                           const StereoTruth& truth, double footprint,
                                           const std::vector<StereoView>& views,
                                           const TriangleMesh* cut, int threads) {
  const ModelEvaluationOptions options = StereoEvaluationOptions(truth, footprint, threads);
  const TruthSurface surface(truth.points, truth.normals, options.truth_spacing, threads);
  StereoTruthEvaluation result;
  ModelDistances to_hull;
  result.hull = EvaluateModel(hull, surface, options, {}, &to_hull);
  const std::vector<SurfaceRegion> regions = {ConcaveRegion(to_hull.truth_to_model, footprint),
                                              TJunctions(truth, views)};
  for (const SurfaceRegion& region : regions)
    result.hull.regions.push_back(EvaluateRegion(region, to_hull, options));
  result.model = EvaluateModel(model, surface, options, regions);
  if (cut) result.cut = EvaluateModel(*cut, surface, options, regions);
  return result;
}

}  // namespace silnet::aggregator
