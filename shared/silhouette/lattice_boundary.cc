#include "shared/silhouette/lattice_boundary.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace silnet {
namespace {

// Expected gap of a boundary whose direction is not a short lattice direction.
constexpr double kCurvedBoundaryGap = 0.25;

// A half-plane normal . x <= offset bounding the boundary polygon: an edge of the centres'
// hull moved outward, a bevel cutting a sharp corner, or an image border.
struct HalfPlane {
  Eigen::Vector2d normal;  // unit, outward
  double offset;
};

// The part of convex `polygon` inside `plane` (Sutherland-Hodgman).
std::vector<Eigen::Vector2d> Clip(const std::vector<Eigen::Vector2d>& polygon,
                                  const HalfPlane& plane) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(polygon.size() + 1);
  const size_t m = polygon.size();
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % m];
    const double da = plane.normal.dot(a) - plane.offset, db = plane.normal.dot(b) - plane.offset;
    if (da <= 0.0) out.push_back(a);
    if ((da <= 0.0) != (db <= 0.0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

double ExpectedBoundaryGap(const Eigen::Vector2d& edge) {
  const auto p = static_cast<long>(std::llround(std::abs(edge.x())));
  const auto q = static_cast<long>(std::llround(std::abs(edge.y())));
  const long g = std::gcd(p, q);
  if (g == 0) return kCurvedBoundaryGap;
  const double spacing = 1.0 / std::hypot(static_cast<double>(p / g), static_cast<double>(q / g));
  return std::max(0.5 * spacing, kCurvedBoundaryGap);
}

std::vector<Eigen::Vector2d> LatticeBoundaryPolygon(const std::vector<Eigen::Vector2d>& centres,
                                                    int width, int height) {
  const size_t n = centres.size();
  const auto outward = [&](size_t i) {
    const Eigen::Vector2d t = (centres[(i + 1) % n] - centres[i]).normalized();
    return Eigen::Vector2d(t.y(), -t.x());
  };
  // The image rectangle, cut by each edge moved out (after a bevel where the corner before
  // it turns by more than a right angle).
  std::vector<Eigen::Vector2d> polygon = {
      {width - 0.5, -0.5}, {width - 0.5, height - 0.5}, {-0.5, height - 0.5}, {-0.5, -0.5}};
  for (size_t i = 0; i < n && polygon.size() >= 3; ++i) {
    const size_t before = (i + n - 1) % n;
    const Eigen::Vector2d normal = outward(i), normal_before = outward(before);
    const double gap = ExpectedBoundaryGap(centres[(i + 1) % n] - centres[i]);
    if (normal.dot(normal_before) < 0.0) {
      const Eigen::Vector2d bisector = (normal + normal_before).normalized();
      const double bevel_gap = std::max(gap, ExpectedBoundaryGap(centres[i] - centres[before]));
      polygon = Clip(polygon, {bisector, bisector.dot(centres[i]) + bevel_gap});
    }
    polygon = Clip(polygon, {normal, normal.dot(centres[i]) + gap});
  }
  if (polygon.size() < 3) return {};
  return polygon;
}

}  // namespace silnet
