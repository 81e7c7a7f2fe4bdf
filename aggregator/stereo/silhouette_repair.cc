#include "aggregator/stereo/silhouette_repair.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Where the ray centre + t * direction (t >= 0) is inside `box`: [t_in, t_out], if anywhere.
std::optional<std::pair<double, double>> ClipRay(const WorldBox& box, const Eigen::Vector3d& centre,
                                                 const Eigen::Vector3d& direction) {
  double t_in = 0, t_out = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-15) {
      if (centre[a] < box.min()[a] || centre[a] > box.max()[a]) return std::nullopt;
      continue;
    }
    double t0 = (box.min()[a] - centre[a]) / direction[a];
    double t1 = (box.max()[a] - centre[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  if (t_in >= t_out) return std::nullopt;
  return std::make_pair(t_in, t_out);
}

// The hull cell a missed pixel's ray should make interior, if its ray meets the hull.
std::optional<size_t> CellForRay(const VoxelGrid& hull, const VoteVolume& votes,
                                 const Eigen::Vector3d& centre, const Eigen::Vector3d& direction) {
  const auto range = ClipRay(hull.Bounds(), centre, direction);
  if (!range) return std::nullopt;
  const double step = 0.5 * hull.voxel_size;
  std::optional<size_t> best;
  float best_votes = 0;
  // The first run through the hull: its first and last sample.
  double run_start = -1, run_end = -1;
  bool run_closed = false;
  // The lattice cell at ray depth t (the hull shares the votes' lattice).
  const auto cell_at = [&](double t) -> std::optional<size_t> {
    const auto ijk = votes.CellOf(centre + t * direction);
    if (!ijk) return std::nullopt;
    return votes.Index((*ijk)[0], (*ijk)[1], (*ijk)[2]);
  };
  for (double t = range->first + 0.5 * step; t < range->second; t += step) {
    const std::optional<size_t> c = cell_at(t);
    if (!c || hull.occupied[*c] == 0) {
      run_closed = run_closed || run_start >= 0;
      continue;
    }
    if (run_start < 0) run_start = t;
    if (!run_closed) run_end = t;
    if (votes.votes[*c] > best_votes) {
      best_votes = votes.votes[*c];
      best = *c;
    }
  }
  if (best) return best;
  if (run_start < 0) return std::nullopt;
  return cell_at(0.5 * (run_start + run_end));
}

}  // namespace

SilhouetteRepair FindSilhouetteRepair(const TriangleMesh& surface, const VoxelGrid& hull,
                                      const VoteVolume& votes,
                                      const std::vector<CameraModel>& cameras,
                                      const std::vector<cv::Mat>& masks, double margin_px) {
  SILNET_CHECK_MSG(cameras.size() == masks.size(), "one mask per camera");
  SILNET_CHECK(hull.dims == votes.dims && votes.votes.size() == votes.size() &&
               hull.occupied.size() == hull.size());
  SilhouetteRepair repair;
  for (size_t v = 0; v < cameras.size(); ++v) {
    const CameraModel& camera = cameras[v];
    SILNET_CHECK_MSG(!camera.HasDistortion(), "the silhouette step needs undistorted cameras");
    SILNET_CHECK_MSG(masks[v].type() == CV_8UC1 && masks[v].cols == camera.width &&
                         masks[v].rows == camera.height,
                     "mask " << v << " does not match its camera's image");
    const cv::Mat covered = RenderMeshSilhouette(surface, camera);
    const cv::Mat inner = InnerSilhouettePixels(masks[v], margin_px);
    const Eigen::Matrix3d back = camera.R.transpose() * camera.K.inverse();
    const Eigen::Vector3d centre = camera.Center();
    for (int y = 0; y < inner.rows; ++y) {
      for (int x = 0; x < inner.cols; ++x) {
        if (inner.at<uint8_t>(y, x) == 0 || covered.at<uint8_t>(y, x) != 0) continue;
        ++repair.missed_pixels;
        const Eigen::Vector3d direction = (back * Eigen::Vector3d(x, y, 1)).normalized();
        const std::optional<size_t> cell = CellForRay(hull, votes, centre, direction);
        if (cell) {
          repair.cells.push_back(*cell);
        } else {
          ++repair.unreachable;
        }
      }
    }
  }
  std::sort(repair.cells.begin(), repair.cells.end());
  repair.cells.erase(std::unique(repair.cells.begin(), repair.cells.end()), repair.cells.end());
  return repair;
}

}  // namespace silnet::aggregator
