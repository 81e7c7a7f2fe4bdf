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

// The true points farther than kConcaveRegionFootprints from the hull: where it cannot reach.
SurfaceRegion ConcaveRegion(const TriangleMesh& hull, const StereoTruth& truth, double footprint) {
  std::vector<double> to_hull;
  EvaluateModel(hull, truth.points, truth.normals, StereoEvaluationOptions(truth, footprint), {},
                &to_hull);
  SurfaceRegion region{kConcaveRegion, std::vector<uint8_t>(to_hull.size())};
  for (size_t i = 0; i < to_hull.size(); ++i)
    region.truth[i] = to_hull[i] > kConcaveRegionFootprints * footprint ? 1 : 0;
  return region;
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

ModelEvaluationOptions StereoEvaluationOptions(const StereoTruth& truth, double footprint) {
  ModelEvaluationOptions options;
  options.footprint = footprint;
  options.truth_spacing = truth.spacing;
  return options;
}

// The regions of the truth measured separately: concave (ConcaveRegion) and the surface
// forming the silhouettes' T-junctions (t_junction_region.h) in the views.
std::vector<SurfaceRegion> StereoTruthRegions(const TriangleMesh& hull, const StereoTruth& truth,
                                              double footprint,
                                              const std::vector<StereoView>& views) {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  for (const StereoView& view : views) {
    cameras.push_back(view.camera);
    masks.push_back(view.mask);
  }
  return {ConcaveRegion(hull, truth, footprint),
          {kTJunctionRegion, TJunctionRegion(truth.points, truth.normals, cameras, masks)}};
}

}  // namespace silnet::aggregator
