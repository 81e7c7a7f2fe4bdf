#include "aggregator/stereo/traded_outer_pixels.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr uint8_t kUnknown = 0, kCoverable = 1, kUncoverable = 2;

// The point where the ray origin + s * direction meets the plane of triangle (a, b, c), if it
// meets it in front of the origin.
std::optional<Eigen::Vector3d> RayMeetsPlane(const Eigen::Vector3d& origin,
                                             const Eigen::Vector3d& direction,
                                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const double along = normal.dot(direction);
  if (along == 0.0) return std::nullopt;
  const double s = normal.dot(a - origin) / along;
  if (!(s > 0)) return std::nullopt;
  return origin + s * direction;
}

}  // namespace

UncoverableInnerPixels::UncoverableInnerPixels(const std::vector<StereoView>& views,
                                               const GrownSilhouettes& grown,
                                               const std::vector<cv::Mat>& inner)
    : views_(views), grown_(grown), inner_(inner) {
  SILNET_CHECK(inner.size() == views.size() && grown.grown.size() == views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    SILNET_CHECK(inner[v].type() == CV_8UC1 && inner[v].size() == views[v].mask.size());
    known_.push_back(cv::Mat::zeros(inner[v].size(), CV_8UC1));
  }
}

bool UncoverableInnerPixels::operator()(size_t v, int x, int y) {
  SILNET_CHECK(v < views_.size());
  if (x < 0 || y < 0 || x >= inner_[v].cols || y >= inner_[v].rows) return false;
  if (inner_[v].at<uint8_t>(y, x) == 0) return false;
  uint8_t& known = known_[v].at<uint8_t>(y, x);
  if (known == kUnknown)
    known = PixelCoverable(views_, grown_, v, x, y) ? kCoverable : kUncoverable;
  return known == kUncoverable;
}

size_t CountOuterCoveredForUncoverable(const TriangleMesh& model, const VertexPixels& projected,
                                       const std::vector<StereoView>& views, size_t v,
                                       const cv::Mat& covered_outer,
                                       UncoverableInnerPixels& uncoverable) {
  SILNET_CHECK(v < views.size());
  SILNET_CHECK(covered_outer.type() == CV_8UC1 && covered_outer.size() == views[v].mask.size());
  if (cv::countNonZero(covered_outer) == 0) return 0;
  // Counts of covered outer pixels over any box, so triangles over none are skipped at once.
  cv::Mat sums;
  cv::integral((covered_outer != 0) / 255, sums, CV_32S);
  const int width = covered_outer.cols, height = covered_outer.rows;
  const CameraModel& camera = views[v].camera;
  const Eigen::Vector3d origin = camera.Center();
  SILNET_CHECK(projected.pixels.size() == model.vertices.size() &&
               projected.in_front.size() == model.vertices.size());
  const auto& [pixels, in_front] = projected;

  cv::Mat traded = cv::Mat::zeros(covered_outer.size(), CV_8UC1);
  size_t count = 0;
  for (const auto& t : model.triangles) {
    const auto ia = static_cast<size_t>(t[0]), ib = static_cast<size_t>(t[1]);
    const auto ic = static_cast<size_t>(t[2]);
    if (!in_front[ia] || !in_front[ib] || !in_front[ic]) continue;
    const Eigen::Vector2d &pa = pixels[ia], &pb = pixels[ib], &pc = pixels[ic];
    // The pixel centres the triangle's box holds (as ForEachPixelInTriangle bounds them).
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.x(), pb.x(), pc.x()}))));
    const int x1 =
        std::min(width - 1, static_cast<int>(std::floor(std::max({pa.x(), pb.x(), pc.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.y(), pb.y(), pc.y()}))));
    const int y1 =
        std::min(height - 1, static_cast<int>(std::floor(std::max({pa.y(), pb.y(), pc.y()}))));
    if (x0 > x1 || y0 > y1) continue;
    if (sums.at<int>(y1 + 1, x1 + 1) - sums.at<int>(y0, x1 + 1) - sums.at<int>(y1 + 1, x0) +
            sums.at<int>(y0, x0) ==
        0) {
      continue;
    }
    const Eigen::Vector3d a = model.vertices[ia].cast<double>();
    const Eigen::Vector3d b = model.vertices[ib].cast<double>();
    const Eigen::Vector3d c = model.vertices[ic].cast<double>();
    ForEachPixelInTriangle(pa, pb, pc, width, height, [&](int x, int y) {
      if (covered_outer.at<uint8_t>(y, x) == 0 || traded.at<uint8_t>(y, x) != 0) return;
      const Eigen::Vector3d direction =
          camera.R.transpose() * camera.PixelRay({static_cast<double>(x), static_cast<double>(y)});
      const auto point = RayMeetsPlane(origin, direction, a, b, c);
      if (!point) return;
      for (size_t j = 0; j < views.size(); ++j) {
        if (j == v) continue;
        const auto q = views[j].camera.Project(*point);
        if (!q) continue;
        // The pixel whose centre is nearest the projection.
        if (uncoverable(j, static_cast<int>(std::floor(q->x() + 0.5)),
                        static_cast<int>(std::floor(q->y() + 0.5)))) {
          traded.at<uint8_t>(y, x) = 255;
          ++count;
          return;
        }
      }
    });
  }
  return count;
}

}  // namespace silnet::aggregator
