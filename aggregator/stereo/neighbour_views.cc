#include "aggregator/stereo/neighbour_views.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace silnet::aggregator {

std::string NeighbourViewOptions::Validate() const {
  if (count < 1) return "neighbour count must be at least 1";
  if (!(min_angle_deg >= 0.0) || !(max_angle_deg <= 180.0) || !(min_angle_deg < max_angle_deg))
    return "neighbour angles must satisfy 0 <= min_angle_deg < max_angle_deg <= 180";
  return {};
}

double ViewingAngleDeg(const CameraModel& a, const CameraModel& b, const Eigen::Vector3d& point) {
  const Eigen::Vector3d da = (a.Center() - point).normalized();
  const Eigen::Vector3d db = (b.Center() - point).normalized();
  const double cosine = std::clamp(da.dot(db), -1.0, 1.0);
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

std::vector<std::vector<int>> SelectNeighbourViews(const std::vector<CameraModel>& cameras,
                                                   const Eigen::Vector3d& object_centre,
                                                   const NeighbourViewOptions& options) {
  std::vector<std::vector<int>> neighbours(cameras.size());
  for (size_t i = 0; i < cameras.size(); ++i) {
    std::vector<std::pair<double, int>> candidates;
    for (size_t j = 0; j < cameras.size(); ++j) {
      if (j == i) continue;
      const double angle = ViewingAngleDeg(cameras[i], cameras[j], object_centre);
      if (angle >= options.min_angle_deg && angle <= options.max_angle_deg)
        candidates.emplace_back(angle, static_cast<int>(j));
    }
    std::sort(candidates.begin(), candidates.end());
    const size_t keep = std::min(candidates.size(), static_cast<size_t>(options.count));
    for (size_t c = 0; c < keep; ++c)
      neighbours[i].push_back(candidates[c].second);
  }
  return neighbours;
}

}  // namespace silnet::aggregator
