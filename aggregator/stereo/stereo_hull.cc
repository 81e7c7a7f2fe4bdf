#include "aggregator/stereo/stereo_hull.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/coincident_cameras.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"
#include "aggregator/stereo/lattice_ray.h"
#include "aggregator/stereo/model_evaluation.h"

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

// The pixel of `camera`'s image nearest to where it sees `point`, if there is one.
std::optional<cv::Point> NearestPixel(const CameraModel& camera, const Eigen::Vector3d& point) {
  const auto uv = camera.Project(point);
  if (!uv) return std::nullopt;
  const int x = static_cast<int>(std::floor(uv->x() + 0.5));
  const int y = static_cast<int>(std::floor(uv->y() + 0.5));
  if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) return std::nullopt;
  return cv::Point(x, y);
}

// The hull of `views` from contours reaching beyond the pixel centres (ComputeStereoHull):
// covering contours first; where they do not close (narrow gaps), the silhouettes grown by a
// pixel with contours just inside the grown pixel centres. `how` names the contours used.
PolyhedralHullResult WidenedHull(const CutSilhouettes& views,
                                 const PolyhedralHullOptions& exact_options, std::string* how) {
  PolyhedralHullOptions covering = exact_options;
  covering.contour_cover_pixel_centres = true;
  covering.contour_cover_offset_px = kWidenedCoverOffsetPx;
  covering.contour_cover_background_slack_px = kWidenedCoverSlackPx;
  PolyhedralHullResult widened = ComputePolyhedralHull(views.cameras, views.masks, covering);
  *how = fmt::format("covering contours {} px beyond the pixel centres", kWidenedCoverOffsetPx);
  if (widened.success) return widened;
  std::vector<cv::Mat> grown(views.masks.size());
  for (size_t v = 0; v < grown.size(); ++v)
    cv::dilate(views.masks[v], grown[v], cv::Mat::ones(3, 3, CV_8UC1));
  PolyhedralHullOptions dilated = exact_options;
  dilated.contour_offset_px = kWidenedGrownOffsetPx;
  *how = "the silhouettes grown by a pixel";
  return ComputePolyhedralHull(views.cameras, grown, dilated);
}

}  // namespace

BorderCarving CarveByBorderViews(const CutSilhouettes& border, const CutSilhouettes& bounded,
                                 double margin_px, VoxelGrid* grid) {
  BorderCarving carving;
  std::vector<size_t> carved;
  for (int k = 0; k < grid->dims[2]; ++k) {
    for (int j = 0; j < grid->dims[1]; ++j) {
      for (int i = 0; i < grid->dims[0]; ++i) {
        const size_t cell = grid->Index(i, j, k);
        if (grid->occupied[cell] == 0 ||
            VoxelCentreInHull(border.cameras, border.masks, grid->Center(i, j, k)))
          continue;
        grid->occupied[cell] = 0;
        carved.push_back(cell);
      }
    }
  }
  carving.carved = carved.size();
  if (carved.empty()) return carving;
  std::vector<uint8_t> was_carved(grid->size(), 0);
  for (size_t cell : carved)
    was_carved[cell] = 1;
  // Rays to give cells back on, found before any is given back.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;
  for (size_t v = 0; v < bounded.cameras.size(); ++v) {
    const CameraModel& camera = bounded.cameras[v];
    // Only pixels a carved cell projects near can have lost their cover.
    cv::Mat near_carved = cv::Mat::zeros(camera.height, camera.width, CV_8UC1);
    for (size_t cell : carved) {
      if (const auto pixel = NearestPixel(camera, grid->CenterOf(cell)))
        near_carved.at<uint8_t>(*pixel) = 255;
    }
    cv::dilate(near_carved, near_carved, cv::Mat::ones(5, 5, CV_8UC1));
    const cv::Mat inner = InnerSilhouettePixels(bounded.masks[v], margin_px);
    const Eigen::Matrix3d back = camera.R.transpose() * camera.K.inverse();
    const Eigen::Vector3d centre = camera.Center();
    for (int y = 0; y < inner.rows; ++y) {
      for (int x = 0; x < inner.cols; ++x) {
        if (inner.at<uint8_t>(y, x) == 0 || near_carved.at<uint8_t>(y, x) == 0) continue;
        const Eigen::Vector3d direction = (back * Eigen::Vector3d(x, y, 1)).normalized();
        bool covered = false, lost = false;
        WalkRay(*grid, centre, direction, [&](double, size_t cell) {
          covered = covered || grid->occupied[cell] != 0;
          lost = lost || was_carved[cell] != 0;
        });
        if (lost && !covered) rays.emplace_back(centre, direction);
      }
    }
  }
  // Per ray, the one carved cell the border views see least far outside their silhouettes.
  std::vector<cv::Mat> outside(border.cameras.size());
  for (size_t v = 0; v < outside.size(); ++v)
    cv::distanceTransform(border.masks[v] == 0, outside[v], cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const auto outside_distance = [&](size_t cell) {
    float worst = 0;
    for (size_t v = 0; v < outside.size(); ++v) {
      if (const auto pixel = NearestPixel(border.cameras[v], grid->CenterOf(cell)))
        worst = std::max(worst, outside[v].at<float>(*pixel));
    }
    return worst;
  };
  for (const auto& [centre, direction] : rays) {
    bool covered = false;
    size_t best = 0, previous = grid->size();
    float best_distance = std::numeric_limits<float>::infinity();
    WalkRay(*grid, centre, direction, [&](double, size_t cell) {
      covered = covered || grid->occupied[cell] != 0;
      if (covered || was_carved[cell] == 0 || cell == previous) return;
      previous = cell;  // the walk's half-cell steps visit most cells twice in a row
      const float distance = outside_distance(cell);
      if (distance < best_distance) best_distance = distance, best = cell;
    });
    if (covered || !std::isfinite(best_distance)) continue;
    grid->occupied[best] = 1;
    ++carving.restored;
  }
  return carving;
}

PolyhedralHullResult ComputeStereoHull(const CutSilhouettes& views, int threads,
                                       std::vector<std::string>* warnings, bool keep_provenance) {
  PolyhedralHullOptions exact_options;
  exact_options.threads = threads;
  exact_options.keep_provenance = keep_provenance;
  PolyhedralHullResult exact = ComputePolyhedralHull(views.cameras, views.masks, exact_options);
  if (exact.stats.merged_cameras > 0) {
    const CoincidentCameras coincident = FindCoincidentCameras(views.cameras);
    for (size_t v = 0; v < views.cameras.size(); ++v) {
      const auto first = static_cast<size_t>(coincident.same_as[v]);
      if (first == v) continue;
      warnings->push_back(
          fmt::format("visual hull: {} was taken from the viewpoint of {}; their silhouettes are "
                      "intersected into one cone",
                      views.cameras[v].id, views.cameras[first].id));
      spdlog::warn("{}", warnings->back());
    }
  }
  if (exact.success) {
    const double missed = MissedInnerShare(exact.mesh, views.cameras, views.masks);
    if (missed <= kWidenedHullMissedShare) return exact;
    std::string how;
    const PolyhedralHullResult widened = WidenedHull(views, exact_options, &how);
    const double widened_missed =
        widened.success ? MissedInnerShare(widened.mesh, views.cameras, views.masks) : 1.0;
    const bool better = widened.success && widened_missed < missed;
    warnings->push_back(fmt::format(
        "visual hull: it misses {:.2f} % of the silhouette pixels >= 1 px inside their outlines "
        "(the cameras and the silhouettes disagree); {}",
        100 * missed,
        better ? fmt::format("built again from {}: {:.2f} % missed", how, 100 * widened_missed)
               : fmt::format("kept: the hull from {} {}", how,
                             widened.success ? "is no better" : "failed: " + widened.reason)));
    spdlog::warn("{}", warnings->back());
    return better ? widened : exact;
  }
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
