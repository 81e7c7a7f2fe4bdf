#pragma once
// Melkman's on-line convex hull of a simple polyline in linear time (thesis 2.3.1, ref. 99).

#include <Eigen/Core>
#include <vector>

namespace silnet {

// Twice the signed area of triangle (a, b, c); > 0 when a -> b -> c turns towards +y from
// +x (positive orientation in pixel coordinates, clockwise on a y-down screen).
inline double Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// The convex hull of the vertices of a simple (non-self-intersecting) polyline, in positive
// orientation, without repeated or collinear vertices. Linear time. Returns fewer than three
// points only if all input points are collinear (then the two extreme points, or one).
std::vector<Eigen::Vector2d> MelkmanHull(const std::vector<Eigen::Vector2d>& polyline);

// The convex hull of points sorted by (y, x) (Andrew's monotone chain, linear time), in
// positive orientation, without repeated or collinear vertices. Unlike MelkmanHull it needs
// no simple polyline: row extents of several blobs are fine.
std::vector<Eigen::Vector2d> SortedPointsHull(const std::vector<Eigen::Vector2d>& sorted);

}  // namespace silnet
