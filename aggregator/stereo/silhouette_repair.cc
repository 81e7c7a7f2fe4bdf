#include "aggregator/stereo/silhouette_repair.h"

#include <algorithm>
#include <optional>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/lattice_ray.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/steps_to_interior.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The hull cell a missed pixel's ray should make interior, if its ray meets the hull: with
// `steps`, the ray's cell nearest the interior within their bound (the most voted of equals),
// else the most voted, else the middle of the ray's first run through the hull.
std::optional<size_t> CellForRay(const VoxelGrid& hull, const VoteVolume& votes,
                                 const StepsToInterior* steps, const Eigen::Vector3d& centre,
                                 const Eigen::Vector3d& direction) {
  std::optional<size_t> best, nearest;
  float best_votes = 0, nearest_votes = -1;
  int nearest_steps = -1;
  // The first run through the hull: its first and last sample.
  double run_start = -1, run_end = -1;
  bool run_closed = false;
  WalkRay(hull, centre, direction, [&](double t, size_t c) {
    if (hull.occupied[c] == 0) {
      run_closed = run_closed || run_start >= 0;
      return;
    }
    if (run_start < 0) run_start = t;
    if (!run_closed) run_end = t;
    const int to_interior = steps != nullptr ? steps->Steps(c) : -1;
    if (to_interior >= 0 && (!nearest || to_interior < nearest_steps ||
                             (to_interior == nearest_steps && votes.votes[c] > nearest_votes))) {
      nearest = c;
      nearest_steps = to_interior;
      nearest_votes = votes.votes[c];
    }
    if (votes.votes[c] > best_votes) {
      best_votes = votes.votes[c];
      best = c;
    }
  });
  if (nearest) return nearest;
  if (best) return best;
  if (run_start < 0) return std::nullopt;
  const auto middle = votes.CellOf(centre + 0.5 * (run_start + run_end) * direction);
  if (!middle) return std::nullopt;
  return votes.Index((*middle)[0], (*middle)[1], (*middle)[2]);
}

}  // namespace

SilhouetteRepair FindSilhouetteRepair(const TriangleMesh& surface, const VoxelGrid& hull,
                                      const VoteVolume& votes,
                                      const std::vector<CameraModel>& cameras,
                                      const std::vector<cv::Mat>& masks, double margin_px,
                                      const StepsToInterior* steps) {
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
        const std::optional<size_t> cell = CellForRay(hull, votes, steps, centre, direction);
        if (!cell) {
          ++repair.unreachable;
          continue;
        }
        repair.cells.push_back(*cell);
        if (steps == nullptr) continue;
        const std::vector<size_t> bridge = steps->Bridge(*cell);
        repair.cells.insert(repair.cells.end(), bridge.begin(), bridge.end());
        if (steps->Steps(*cell) > 0) ++repair.joined;
      }
    }
  }
  std::sort(repair.cells.begin(), repair.cells.end());
  repair.cells.erase(std::unique(repair.cells.begin(), repair.cells.end()), repair.cells.end());
  return repair;
}

}  // namespace silnet::aggregator
