#pragma once
// Tangent queries on a SilhouetteHull (thesis 2.3.1): the tangent with a given direction,
// through the tangent table, and the two outer tangents from an external point (an
// epipole), each in O(log k) for a k-vertex hull.

#include <Eigen/Core>
#include <optional>

#include "shared/silhouette/silhouette_hull.h"

namespace silnet {

// The vertex touched by the directed tangent line of direction `angle` (radians) that has the
// hull on its left: the vertex i with angle in [edge_angle(i - 1), edge_angle(i)] (mod 2 pi).
// Binary search on the tangent table. The hull must be non-empty.
int SupportingVertex(const SilhouetteHull& hull, double angle);

// The two outer tangents from a point to a hull.
struct PointTangents {
  int left = -1;   // vertex of the tangent with the hull on the left of the line point -> vertex
  int right = -1;  // vertex of the tangent with the hull on the right
};

// Outer tangents from `point`, given homogeneously (x, y, w): w = 1 for an image point, w = 0
// for a point at infinity (then the tangents are parallel to (x, y)). nullopt if the point
// is inside or on the hull, or the hull has fewer than three vertices. O(log k) by binary
// search over the hull's vertices, verified, with a linear scan as the fallback for
// degenerate (collinear) configurations.
std::optional<PointTangents> TangentsFromPoint(const SilhouetteHull& hull,
                                               const Eigen::Vector3d& point);

// The same by brute force, O(k): the reference for tests.
std::optional<PointTangents> TangentsFromPointLinear(const SilhouetteHull& hull,
                                                     const Eigen::Vector3d& point);

// The homogeneous line through `point` (homogeneous, as above) and hull vertex `vertex`.
Eigen::Vector3d TangentLine(const SilhouetteHull& hull, const Eigen::Vector3d& point, int vertex);

}  // namespace silnet
