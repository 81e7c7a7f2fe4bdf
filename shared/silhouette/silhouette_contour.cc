#include "shared/silhouette/silhouette_contour.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet {
namespace {

// Moves the points of a ring traced through boundary pixel centres onto the boundary: `offset`
// lattice steps (half of one puts it on the pixel edges) along the normal towards the
// background, `side` = +1 when the background lies to the right of the traced direction
// (pixel coordinates), -1 when to the left.
std::vector<cv::Point2f> OffsetToBoundary(const std::vector<cv::Point>& ring, double side,
                                          float offset) {
  const size_t n = ring.size();
  std::vector<cv::Point2f> out(n);
  for (size_t i = 0; i < n; ++i) {
    const cv::Point& prev = ring[(i + n - 1) % n];
    const cv::Point& next = ring[(i + 1) % n];
    cv::Point2f tangent(static_cast<float>(next.x - prev.x), static_cast<float>(next.y - prev.y));
    if (tangent.x == 0 && tangent.y == 0) {
      tangent = cv::Point2f(static_cast<float>(ring[i].x - prev.x),
                            static_cast<float>(ring[i].y - prev.y));
    }
    const float length = std::hypot(tangent.x, tangent.y);
    cv::Point2f normal(0, 0);
    if (length > 0) normal = cv::Point2f(-tangent.y, tangent.x) * static_cast<float>(side / length);
    const float step = offset / std::max(1.0f, std::abs(normal.x) + std::abs(normal.y));
    out[i] =
        cv::Point2f(static_cast<float>(ring[i].x), static_cast<float>(ring[i].y)) + normal * step;
  }
  return out;
}

// Replaces every point of a closed ring by the [1 2 1] / 4 average with its neighbours,
// `passes` times: the pixel staircase's zig-zag shrinks, so simplification keeps fewer points.
void SmoothRing(std::vector<cv::Point2f>& ring, int passes) {
  const size_t n = ring.size();
  if (n < 3) return;
  std::vector<cv::Point2f> smoothed(n);
  for (int pass = 0; pass < passes; ++pass) {
    for (size_t i = 0; i < n; ++i)
      smoothed[i] = 0.25f * (ring[(i + n - 1) % n] + ring[(i + 1) % n]) + 0.5f * ring[i];
    ring.swap(smoothed);
  }
}

std::vector<Eigen::Vector2f> Simplify(const std::vector<cv::Point2f>& ring, double tolerance) {
  std::vector<cv::Point2f> simplified;
  if (ring.size() >= 3) {
    cv::approxPolyDP(ring, simplified, tolerance, true);
  } else {
    simplified = ring;
  }
  std::vector<Eigen::Vector2f> out;
  out.reserve(simplified.size());
  for (const cv::Point2f& p : simplified)
    out.emplace_back(p.x, p.y);
  return out;
}

}  // namespace

double RingArea(const std::vector<Eigen::Vector2f>& ring) {
  double twice = 0.0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2f& a = ring[i];
    const Eigen::Vector2f& b = ring[(i + 1) % ring.size()];
    twice += static_cast<double>(a.x()) * b.y() - static_cast<double>(b.x()) * a.y();
  }
  return 0.5 * twice;
}

size_t SilhouetteContours::PointCount() const {
  size_t count = 0;
  for (const ContourPolygon& p : polygons) {
    count += p.outer.size();
    for (const auto& h : p.holes)
      count += h.size();
  }
  return count;
}

double SilhouetteContours::Area() const {
  double area = 0.0;
  for (const ContourPolygon& p : polygons) {
    area += RingArea(p.outer);
    for (const auto& h : p.holes)
      area += RingArea(h);
  }
  return area;
}

SilhouetteContours ExtractContours(const cv::Mat& mask, const ContourOptions& options) {
  SILNET_CHECK_MSG(mask.type() == CV_8UC1, "silhouette masks are CV_8UC1, got " << mask.type());
  std::vector<std::vector<cv::Point>> rings;
  std::vector<cv::Vec4i> hierarchy;
  // findContours treats non-zero pixels as foreground and leaves its input alone (OpenCV >=
  // 3.2); only the foreground's box matters.
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return {};
  cv::findContours(mask(box), rings, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE, box.tl());
  SilhouetteContours contours;
  for (size_t i = 0; i < rings.size(); ++i) {
    if (hierarchy[i][3] >= 0) continue;  // a hole; handled with its parent
    // Orientation of the traced ring decides on which side the background is.
    auto to_boundary = [&](const std::vector<cv::Point>& ring, bool hole) {
      double traced = 0.0;  // twice the signed area, same convention as RingArea
      for (size_t k = 0; k < ring.size(); ++k) {
        const cv::Point& a = ring[k];
        const cv::Point& b = ring[(k + 1) % ring.size()];
        traced += static_cast<double>(a.x) * b.y - static_cast<double>(b.x) * a.y;
      }
      // For an outer ring the background is outside; for a hole, inside the traced ring.
      double side = traced >= 0 ? -1.0 : 1.0;
      if (hole) side = -side;
      std::vector<cv::Point2f> boundary =
          OffsetToBoundary(ring, side, static_cast<float>(options.boundary_offset_px));
      SmoothRing(boundary, options.smoothing_passes);
      return boundary;
    };
    ContourPolygon polygon;
    polygon.outer = Simplify(to_boundary(rings[i], false), options.tolerance_px);
    if (RingArea(polygon.outer) < 0) std::reverse(polygon.outer.begin(), polygon.outer.end());
    if (std::abs(RingArea(polygon.outer)) < options.min_region_area) continue;
    for (int child = hierarchy[i][2]; child >= 0;
         child = hierarchy[static_cast<size_t>(child)][0]) {
      std::vector<Eigen::Vector2f> hole =
          Simplify(to_boundary(rings[static_cast<size_t>(child)], true), options.tolerance_px);
      if (RingArea(hole) > 0) std::reverse(hole.begin(), hole.end());
      if (std::abs(RingArea(hole)) >= options.min_hole_area)
        polygon.holes.push_back(std::move(hole));
    }
    contours.polygons.push_back(std::move(polygon));
  }
  return contours;
}

bool ContoursContain(const SilhouetteContours& contours, const Eigen::Vector2f& point) {
  bool inside = false;
  auto crossings = [&](const std::vector<Eigen::Vector2f>& ring) {
    for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
      const Eigen::Vector2f& a = ring[i];
      const Eigen::Vector2f& b = ring[j];
      if ((a.y() > point.y()) != (b.y() > point.y()) &&
          point.x() < (b.x() - a.x()) * (point.y() - a.y()) / (b.y() - a.y()) + a.x()) {
        inside = !inside;
      }
    }
  };
  for (const ContourPolygon& p : contours.polygons) {
    if (p.outer.size() >= 3) crossings(p.outer);
    for (const auto& h : p.holes) {
      if (h.size() >= 3) crossings(h);
    }
  }
  return inside;
}

}  // namespace silnet
