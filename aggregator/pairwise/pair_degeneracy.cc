#include "aggregator/pairwise/pair_degeneracy.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "shared/silhouette/hull_tangents.h"

namespace silnet::aggregator {
namespace {

// RMS distance to the centroid and the sum of squared distances.
std::pair<double, double> Spread(const std::vector<Eigen::Vector2d>& points) {
  if (points.empty()) return {0.0, 0.0};
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points)
    mean += p;
  mean /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const auto& p : points)
    sum += (p - mean).squaredNorm();
  return {std::sqrt(sum / static_cast<double>(points.size())), sum};
}

}  // namespace

SupportDiagnosis DiagnoseSupport(const EpipolarModel& model, const std::vector<TimedMatch>& inliers,
                                 const SilhouetteSequence& i, const SilhouetteSequence& j,
                                 const DegeneracyLimits& limits) {
  SupportDiagnosis d;
  size_t frames = 0, inside = 0;
  for (const SilhouetteFrame& f : i.frames) {
    if (i.Usable(f.index) == nullptr) continue;
    ++frames;
    const bool in_i = !TangentsFromPoint(f.hull, model.pencil_i.e).has_value();
    const SilhouetteFrame* fj = j.Usable(static_cast<uint64_t>(
        std::max(0.0, std::round(static_cast<double>(f.index) + model.offset))));
    const bool in_j = fj != nullptr && !TangentsFromPoint(fj->hull, model.pencil_j.e).has_value();
    if (in_i || in_j) ++inside;
  }
  d.epipole_inside_fraction =
      frames > 0 ? static_cast<double>(inside) / static_cast<double>(frames) : 1.0;
  std::vector<Eigen::Vector2d> xi, xj;
  std::vector<cv::Point2f> cvi, cvj;
  for (const TimedMatch& m : inliers) {
    xi.push_back(m.x_i);
    xj.push_back(m.XjAt(model.offset));
    cvi.emplace_back(static_cast<float>(m.x_i.x()), static_cast<float>(m.x_i.y()));
    cvj.emplace_back(static_cast<float>(xj.back().x()), static_cast<float>(xj.back().y()));
  }
  const auto [rms_i, sum_i] = Spread(xi);
  const auto [rms_j, sum_j] = Spread(xj);
  d.spread_i = rms_i;
  d.spread_j = rms_j;
  d.spread_score = sum_i + sum_j;
  if (inliers.size() >= 8) {
    cv::Mat mask;
    const cv::Mat homography = cv::findHomography(cvi, cvj, cv::RANSAC, 1.5, mask, 2000, 0.999);
    if (!homography.empty()) {
      d.planar_fraction =
          static_cast<double>(cv::countNonZero(mask)) / static_cast<double>(inliers.size());
    }
  }
  const double diagonal_i = std::hypot(i.width, i.height),
               diagonal_j = std::hypot(j.width, j.height);
  if (d.epipole_inside_fraction > limits.max_epipole_inside) {
    d.reason = fmt::format("epipoles inside the silhouettes in {:.0f}% of frames",
                           100.0 * d.epipole_inside_fraction);
  } else if (inliers.size() < limits.min_inliers) {
    d.reason = fmt::format("too few frontier point correspondences ({} < {})", inliers.size(),
                           limits.min_inliers);
  } else if (rms_i < limits.min_spread_fraction * diagonal_i ||
             rms_j < limits.min_spread_fraction * diagonal_j) {
    d.reason = fmt::format(
        "too little motion: frontier points within {:.0f} px and {:.0f} px of their centres", rms_i,
        rms_j);
  } else if (d.planar_fraction > limits.max_planar_fraction) {
    d.reason = fmt::format("frontier points near a plane: a homography explains {:.0f}% of them",
                           100.0 * d.planar_fraction);
  }
  return d;
}

}  // namespace silnet::aggregator
