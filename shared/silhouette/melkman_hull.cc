#include "shared/silhouette/melkman_hull.h"

#include <algorithm>
#include <deque>

namespace silnet {

std::vector<Eigen::Vector2d> MelkmanHull(const std::vector<Eigen::Vector2d>& polyline) {
  // Drop consecutive duplicates.
  std::vector<Eigen::Vector2d> points;
  points.reserve(polyline.size());
  for (const Eigen::Vector2d& p : polyline) {
    if (points.empty() || p != points.back()) points.push_back(p);
  }
  if (points.size() > 1 && points.front() == points.back()) points.pop_back();
  // Find the first point that is not collinear with the first two.
  size_t third = 2;
  while (third < points.size() && Orientation(points[0], points[1], points[third]) == 0.0) {
    ++third;
  }
  if (third >= points.size()) {
    // Collinear: the two extreme points.
    if (points.size() <= 1) return points;
    size_t lo = 0, hi = 0;
    const Eigen::Vector2d dir = points[1] - points[0];
    for (size_t i = 1; i < points.size(); ++i) {
      if (points[i].dot(dir) < points[lo].dot(dir)) lo = i;
      if (points[i].dot(dir) > points[hi].dot(dir)) hi = i;
    }
    return {points[lo], points[hi]};
  }
  // The deque holds the hull in positive orientation with the newest point at both ends.
  std::deque<Eigen::Vector2d> d;
  const Eigen::Vector2d& a = points[third - 1];
  const Eigen::Vector2d& b = points[third];
  if (Orientation(points[0], a, b) > 0) {
    d = {b, points[0], a, b};
  } else {
    d = {b, a, points[0], b};
  }
  for (size_t i = third + 1; i < points.size(); ++i) {
    const Eigen::Vector2d& v = points[i];
    // Inside the current hull: both end edges see v on their inner side.
    if (Orientation(d[d.size() - 2], d.back(), v) > 0 && Orientation(v, d[0], d[1]) > 0) continue;
    while (d.size() > 2 && Orientation(d[d.size() - 2], d.back(), v) <= 0)
      d.pop_back();
    d.push_back(v);
    while (d.size() > 2 && Orientation(v, d[0], d[1]) <= 0)
      d.pop_front();
    d.push_front(v);
  }
  // Vertices of the starting triangle may end up collinear with their neighbours.
  std::vector<Eigen::Vector2d> hull(d.begin(), d.end() - 1);
  bool removed = true;
  while (removed && hull.size() > 3) {
    removed = false;
    for (size_t i = 0; i < hull.size() && hull.size() > 3; ++i) {
      const size_t n = hull.size();
      if (Orientation(hull[(i + n - 1) % n], hull[i], hull[(i + 1) % n]) <= 0.0) {
        hull.erase(hull.begin() + static_cast<std::ptrdiff_t>(i));
        removed = true;
      }
    }
  }
  return hull;
}

std::vector<Eigen::Vector2d> SortedPointsHull(const std::vector<Eigen::Vector2d>& sorted) {
  const size_t n = sorted.size();
  if (n < 3) {
    std::vector<Eigen::Vector2d> out(sorted);
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  // One chain forward and one back; a point joins after popping points it makes turn the
  // wrong way (or go straight on).
  std::vector<Eigen::Vector2d> hull(2 * n);
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    while (k >= 2 && Orientation(hull[k - 2], hull[k - 1], sorted[i]) >= 0.0)
      --k;
    hull[k++] = sorted[i];
  }
  for (size_t i = n - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Orientation(hull[k - 2], hull[k - 1], sorted[i]) >= 0.0)
      --k;
    hull[k++] = sorted[i];
  }
  hull.resize(k - 1);
  if (hull.size() < 3) return hull;
  // The chains above run against the positive orientation.
  std::reverse(hull.begin(), hull.end());
  return hull;
}

}  // namespace silnet
