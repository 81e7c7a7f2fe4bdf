#include "shared/silhouette/silhouette_contour.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "shared/silhouette/border_tracing.h"
#include "shared/silhouette/covering_contour.h"
#include "shared/silhouette/douglas_peucker.h"
#include "shared/silhouette/foreground_box.h"
#include "shared/util/check.h"

namespace silnet {
namespace {

// The indexes before and after `i` on a closed ring of `n` points.
size_t Before(size_t i, size_t n) {
  return i == 0 ? n - 1 : i - 1;
}
size_t After(size_t i, size_t n) {
  return i + 1 == n ? 0 : i + 1;
}

// How far a ring point moves (see OffsetToBoundary) where `tangent` runs from the point before
// it to the one after it, or, at the end of a one pixel wide line (`end`), from the one before
// to itself.
cv::Point2f BoundaryShift(cv::Point2f tangent, bool end, double side, float offset,
                          bool ends_outward) {
  const float length = std::hypot(tangent.x, tangent.y);
  cv::Point2f normal(0, 0);
  if (length > 0 && end && ends_outward) {
    normal = tangent / length;
  } else if (length > 0) {
    normal = cv::Point2f(-tangent.y, tangent.x) * static_cast<float>(side / length);
  }
  const float step = offset / std::max(1.0f, std::abs(normal.x) + std::abs(normal.y));
  return normal * step;
}

// BoundaryShift for one extraction's `offset` and `ends_outward`, read from a table for the
// tangents an 8-connected ring has (coordinates in [-2, 2], side +1 or -1) and computed for
// any other: the table holds BoundaryShift's own results, so both give the same bits.
class BoundaryShifts {
 public:
  BoundaryShifts(float offset, bool ends_outward) : offset_(offset), ends_outward_(ends_outward) {
    for (const double side : {-1.0, 1.0}) {
      for (const bool end : {false, true}) {
        for (int dy = -kReach; dy <= kReach; ++dy) {
          for (int dx = -kReach; dx <= kReach; ++dx) {
            table_[Slot(cv::Point(dx, dy), end, side)] =
                BoundaryShift(cv::Point2f(static_cast<float>(dx), static_cast<float>(dy)), end,
                              side, offset_, ends_outward_);
          }
        }
      }
    }
  }

  cv::Point2f Shift(cv::Point tangent, bool end, double side) const {
    const bool listed = std::abs(tangent.x) <= kReach && std::abs(tangent.y) <= kReach &&
                        (side == 1.0 || side == -1.0);
    if (listed) return table_[Slot(tangent, end, side)];
    return BoundaryShift(cv::Point2f(static_cast<float>(tangent.x), static_cast<float>(tangent.y)),
                         end, side, offset_, ends_outward_);
  }

 private:
  static constexpr int kReach = 2, kWidth = 2 * kReach + 1;

  static size_t Slot(cv::Point tangent, bool end, double side) {
    const int page = (side > 0 ? 2 : 0) + (end ? 1 : 0);
    return static_cast<size_t>((page * kWidth + tangent.y + kReach) * kWidth + tangent.x + kReach);
  }

  float offset_;
  bool ends_outward_;
  std::array<cv::Point2f, 4 * kWidth * kWidth> table_;
};

// Moves the points of a ring traced through boundary pixel centres onto the boundary by
// `shifts` (`offset` lattice steps, half of one puts them on the pixel edges, along the normal
// towards the background), `side` = +1 when the background lies to the right of the traced
// direction (pixel coordinates), -1 when to the left. At the end of a one pixel wide line (the
// ring turns back) the point moves along the line, out of its end, if the shifts' `ends_outward`,
// else across.
std::vector<cv::Point2f> OffsetToBoundary(const std::vector<cv::Point>& ring, double side,
                                          const BoundaryShifts& shifts) {
  const size_t n = ring.size();
  std::vector<cv::Point2f> out(n);
  for (size_t i = 0; i < n; ++i) {
    const cv::Point& prev = ring[Before(i, n)];
    cv::Point tangent = ring[After(i, n)] - prev;
    const bool end = tangent.x == 0 && tangent.y == 0;
    if (end) tangent = ring[i] - prev;
    out[i] = cv::Point2f(static_cast<float>(ring[i].x), static_cast<float>(ring[i].y)) +
             shifts.Shift(tangent, end, side);
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
    for (size_t i = 0; i < n; ++i) {
      smoothed[i] = 0.25f * (ring[Before(i, n)] + ring[After(i, n)]) + 0.5f * ring[i];
    }
    ring.swap(smoothed);
  }
}

std::vector<Eigen::Vector2f> Simplify(const std::vector<cv::Point2f>& ring, double tolerance) {
  const std::vector<cv::Point2f> simplified =
      ring.size() >= 3 ? SimplifyClosedRing(ring, tolerance) : ring;
  std::vector<Eigen::Vector2f> out;
  out.reserve(simplified.size());
  for (const cv::Point2f& p : simplified)
    out.emplace_back(p.x, p.y);
  return out;
}

// Appends the two background pixel centres next to boundary pixel `centre` that lie farthest
// towards its outline point `outline`, one across an edge and one across a corner (NaN where
// there is none); outside the image counts as background.
void AddBackgroundNeighbours(const cv::Mat& mask, const cv::Point& centre,
                             const cv::Point2f& outline, std::vector<Eigen::Vector2f>& out) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Point2f outward(outline.x - static_cast<float>(centre.x),
                            outline.y - static_cast<float>(centre.y));
  for (const bool diagonal : {false, true}) {
    Eigen::Vector2f best(nan, nan);
    float best_dot = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx != 0 && dy != 0) != diagonal || (dx == 0 && dy == 0)) continue;
        const int x = centre.x + dx, y = centre.y + dy;
        const bool inside = x >= 0 && y >= 0 && x < mask.cols && y < mask.rows;
        if (inside && mask.at<uint8_t>(y, x) != 0) continue;
        const float dot = static_cast<float>(dx) * outward.x + static_cast<float>(dy) * outward.y;
        if (dot > best_dot) {
          best_dot = dot;
          best = Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y));
        }
      }
    }
    out.push_back(best);
  }
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
  // Non-zero pixels are foreground; only the foreground's box matters.
  const cv::Rect box = ForegroundBox(mask);
  if (box.area() == 0) return {};
  TraceBorders(mask, box, rings, hierarchy);
  // The boundary moves, once for every ring of the mask.
  const BoundaryShifts shifts(static_cast<float>(options.boundary_offset_px),
                              options.cover_pixel_centres);
  // Orientation of the traced ring decides on which side the background is.
  auto to_boundary = [&](const std::vector<cv::Point>& ring, bool hole) {
    double traced = 0.0;  // twice the signed area, same convention as RingArea
    for (size_t k = 0; k < ring.size(); ++k) {
      const cv::Point& a = ring[k];
      const cv::Point& b = ring[After(k, ring.size())];
      traced += static_cast<double>(a.x) * b.y - static_cast<double>(b.x) * a.y;
    }
    // For an outer ring the background is outside; for a hole, inside the traced ring.
    double side = traced >= 0 ? -1.0 : 1.0;
    if (hole) side = -side;
    // Smoothing pulls the points of narrow tips back onto (or inside) their pixel centres:
    // for the covering simplification a point moves only where it lands farther out.
    const bool cover = options.cover_pixel_centres;
    std::vector<cv::Point2f> boundary = OffsetToBoundary(ring, side, shifts);
    if (!cover) {
      SmoothRing(boundary, options.smoothing_passes);
    } else if (options.smoothing_passes > 0) {
      std::vector<cv::Point2f> smoothed = boundary;
      SmoothRing(smoothed, options.smoothing_passes);
      for (size_t k = 0; k < boundary.size(); ++k) {
        const cv::Point2f centre(static_cast<float>(ring[k].x), static_cast<float>(ring[k].y));
        const cv::Point2f normal = boundary[k] - centre;
        if ((smoothed[k] - centre).dot(normal) >= normal.dot(normal)) boundary[k] = smoothed[k];
      }
    }
    return boundary;
  };
  // Every ring (outer rings and their holes, in that order) and the polygon it belongs to.
  std::vector<std::vector<Eigen::Vector2f>> simplified;
  std::vector<int> owner;  // index of the outer ring, or -1 for an outer ring
  std::vector<TracedRing> traced;
  for (size_t i = 0; i < rings.size(); ++i) {
    if (hierarchy[i][3] >= 0) continue;  // a hole; handled with its parent
    const int outer = static_cast<int>(owner.size());
    auto add = [&](const std::vector<cv::Point>& ring, bool hole) {
      owner.push_back(hole ? outer : -1);
      const std::vector<cv::Point2f> boundary = to_boundary(ring, hole);
      if (!options.cover_pixel_centres) {
        simplified.push_back(Simplify(boundary, options.tolerance_px));
        return;
      }
      TracedRing t;
      for (size_t k = 0; k < ring.size(); ++k) {
        t.centres.emplace_back(static_cast<float>(ring[k].x), static_cast<float>(ring[k].y));
        t.outline.emplace_back(boundary[k].x, boundary[k].y);
        AddBackgroundNeighbours(mask, ring[k], boundary[k], t.background);
      }
      // The silhouette on the left: outer rings positive, holes negative.
      if ((RingArea(t.outline) < 0) != hole) {
        std::reverse(t.centres.begin(), t.centres.end());
        std::reverse(t.outline.begin(), t.outline.end());
        std::reverse(t.background.begin(), t.background.end());  // pairs stay together
      }
      traced.push_back(std::move(t));
    };
    add(rings[i], false);
    for (int child = hierarchy[i][2]; child >= 0; child = hierarchy[static_cast<size_t>(child)][0])
      add(rings[static_cast<size_t>(child)], true);
  }
  if (options.cover_pixel_centres) {
    CoveringOptions covering;
    covering.margin_px = options.cover_margin_px;
    covering.background_slack_px = options.cover_background_slack_px;
    simplified = SimplifyCovering(traced, covering);
  }
  SilhouetteContours contours;
  std::vector<int> polygon_of(owner.size(), -1);
  for (size_t r = 0; r < simplified.size(); ++r) {
    std::vector<Eigen::Vector2f>& ring = simplified[r];
    const bool hole = owner[r] >= 0;
    if ((RingArea(ring) < 0) != hole) std::reverse(ring.begin(), ring.end());
    if (!hole) {
      if (std::abs(RingArea(ring)) < options.min_region_area) continue;
      polygon_of[r] = static_cast<int>(contours.polygons.size());
      contours.polygons.emplace_back();
      contours.polygons.back().outer = std::move(ring);
      continue;
    }
    const int polygon = polygon_of[static_cast<size_t>(owner[r])];
    if (polygon >= 0 && std::abs(RingArea(ring)) >= options.min_hole_area)
      contours.polygons[static_cast<size_t>(polygon)].holes.push_back(std::move(ring));
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
