#include "aggregator/stereo/t_junction_region.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Angle (degrees) at outline point i between the chords to its neighbours `arm` steps away,
// or 180 when the turn is outward (the chord's midpoint inside the silhouette).
double InwardAngle(const std::vector<cv::Point>& outline, size_t i, int arm, const cv::Mat& mask) {
  const auto n = static_cast<long>(outline.size());
  const cv::Point p = outline[i];
  const cv::Point a = outline[static_cast<size_t>((static_cast<long>(i) - arm + n) % n)];
  const cv::Point b = outline[static_cast<size_t>((static_cast<long>(i) + arm) % n)];
  const cv::Point2d u = a - p, w = b - p;
  const double lengths = std::hypot(u.x, u.y) * std::hypot(w.x, w.y);
  if (lengths == 0) return 180;
  const cv::Point mid((a.x + b.x) / 2, (a.y + b.y) / 2);
  const bool inside = mid.x >= 0 && mid.y >= 0 && mid.x < mask.cols && mid.y < mask.rows &&
                      mask.at<uint8_t>(mid) != 0;
  if (inside) return 180;
  return std::acos(std::clamp(u.dot(w) / lengths, -1.0, 1.0)) * 180 / M_PI;
}

}  // namespace

bool TJunctionOptions::IsValid(std::string* reason) const {
  const auto fail = [reason](const char* why) {
    if (reason != nullptr) *reason = why;
    return false;
  };
  if (arm_px < 2) return fail("arm_px must be >= 2");
  if (!(max_angle_deg > 0 && max_angle_deg < 180))
    return fail("max_angle_deg must lie in (0, 180)");
  if (!(radius_px > 0)) return fail("radius_px must be > 0");
  if (!(max_rim_cosine > 0 && max_rim_cosine <= 1))
    return fail("max_rim_cosine must lie in (0, 1]");
  return true;
}

std::vector<cv::Point> InwardOutlineCorners(const cv::Mat& mask, const TJunctionOptions& options) {
  std::string why;
  SILNET_CHECK_MSG(options.IsValid(&why), why);
  SILNET_CHECK(mask.type() == CV_8UC1);
  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(mask != 0, outlines, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  std::vector<cv::Point> corners;
  for (const std::vector<cv::Point>& outline : outlines) {
    if (outline.size() < static_cast<size_t>(4 * options.arm_px)) continue;
    std::vector<double> angle(outline.size());
    for (size_t i = 0; i < outline.size(); ++i)
      angle[i] = InwardAngle(outline, i, options.arm_px, mask);
    // The sharpest point of each run of corner points (runs do not wrap: a whole outline of
    // corner points is no outline of a part).
    size_t i = 0;
    while (i < outline.size()) {
      if (angle[i] >= options.max_angle_deg) {
        ++i;
        continue;
      }
      size_t best = i;
      for (; i < outline.size() && angle[i] < options.max_angle_deg; ++i) {
        if (angle[i] < angle[best]) best = i;
      }
      corners.push_back(outline[best]);
    }
  }
  return corners;
}

std::vector<uint8_t> TJunctionRegion(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals,
                                     const std::vector<CameraModel>& cameras,
                                     const std::vector<cv::Mat>& masks,
                                     const TJunctionOptions& options) {
  SILNET_CHECK(points.size() == normals.size() && cameras.size() == masks.size());
  std::vector<uint8_t> region(points.size(), 0);
  for (size_t v = 0; v < cameras.size(); ++v) {
    // Pixels within radius_px of a corner.
    cv::Mat near = cv::Mat::zeros(masks[v].size(), CV_8UC1);
    for (const cv::Point& corner : InwardOutlineCorners(masks[v], options))
      cv::circle(near, corner, static_cast<int>(std::ceil(options.radius_px)), 255, cv::FILLED);
    const Eigen::Vector3d centre = cameras[v].Center();
    for (size_t p = 0; p < points.size(); ++p) {
      if (region[p] != 0) continue;
      const Eigen::Vector3d ray = (points[p] - centre).normalized();
      if (std::abs(ray.dot(normals[p])) > options.max_rim_cosine) continue;
      const auto pixel = cameras[v].Project(points[p]);
      if (!pixel) continue;
      const int x = static_cast<int>(std::lround(pixel->x())),
                y = static_cast<int>(std::lround(pixel->y()));
      if (x >= 0 && y >= 0 && x < near.cols && y < near.rows && near.at<uint8_t>(y, x) != 0)
        region[p] = 1;
    }
  }
  return region;
}

}  // namespace silnet::aggregator
