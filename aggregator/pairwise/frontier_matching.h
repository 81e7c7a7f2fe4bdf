#pragma once
// Frontier point correspondences from outer epipolar tangents (thesis 2.2-2.3): from each
// hypothesised epipole the two outer tangents of the silhouette's convex hull touch it at
// the images of extremal frontier points; tangents of the two views correspond through the
// epipolar line homography. For a fractional time offset the tangents of view j are
// interpolated between its two neighbouring frames.

#include <Eigen/Core>

#include "aggregator/pairwise/epipolar_model.h"
#include "shared/silhouette/silhouette_hull.h"

namespace silnet::aggregator {

// The two outer tangents from an epipole to one hull: index 0 has the hull on the left of
// the line epipole -> touch point, index 1 on the right.
struct OuterTangents {
  Eigen::Vector2d point[2];
  bool valid[2] = {false, false};  // false where the touch point lies on a clipped edge
  bool exists = false;             // false if the epipole is inside the hull
};

// Outer tangents of `hull` from the homogeneous point `epipole`.
OuterTangents ComputeOuterTangents(const SilhouetteHull& hull, const Eigen::Vector3d& epipole);

// The tangents of view j at a fractional frame: touch points interpolated linearly between
// the tangents `a` (weight 1 - fraction) and `b` (weight fraction); valid where both are.
OuterTangents Interpolate(const OuterTangents& a, const OuterTangents& b, double fraction);

// One frontier point correspondence.
struct FrontierMatch {
  Eigen::Vector2d x_i;
  Eigen::Vector2d x_j;
  int side = 0;     // which tangent of view i (0 or 1)
  int partner = 0;  // which tangent of view j it matched
};

// Pairs the tangents of the two views through the model's line homography (each tangent of i
// goes to the tangent of j nearest to its transferred line) and returns the valid pairs.
int MatchTangents(const EpipolarModel& model, const OuterTangents& ti, const OuterTangents& tj,
                  FrontierMatch out[2]);

}  // namespace silnet::aggregator
