#include "aggregator/stereo/stereo_hull.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"

namespace silnet::aggregator {
namespace {

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

}  // namespace

bool TouchesBorder(const cv::Mat& mask) {
  return cv::countNonZero(mask.row(0)) > 0 || cv::countNonZero(mask.row(mask.rows - 1)) > 0 ||
         cv::countNonZero(mask.col(0)) > 0 || cv::countNonZero(mask.col(mask.cols - 1)) > 0;
}

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

}  // namespace silnet::aggregator
