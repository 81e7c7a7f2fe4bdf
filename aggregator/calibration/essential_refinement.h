#pragma once
// Relative pose refinement with known intrinsics (beyond the thesis, which decomposes the
// pairwise fundamental matrix as it is): a fundamental matrix estimated from epipolar
// tangents has seven degrees of freedom, an essential one five, and the essential matrix
// nearest to K_j^T F K_i in the Frobenius sense is not the pose the correspondences support
// best. On real silhouettes (Utrecht) the decomposed poses of one pair's candidates lay 2-26
// degrees from the capture's own calibration; refined on their correspondences most came within
// 1-3 degrees. The refinement minimises the Sampson distance of the correspondences, in
// pixels, over the rotation and the direction of the translation, with a robust loss.

#include <vector>

#include "aggregator/calibration/relative_pose.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the refinement.
struct EssentialRefinementOptions {
  double loss_px = 1.0;     // Cauchy scale of the Sampson distance
  int max_iterations = 50;  // Levenberg-Marquardt iterations at most
};

// `start` (x_j = R x_i + t) refined on correspondences between camera_i and camera_j (pixels,
// with each camera's distortion); the rotation stays a rotation and |t| = 1. Returns `start`
// unchanged with fewer than 5 correspondences or if the solver does not produce a usable
// solution.
RelativePose RefineRelativePose(const CameraModel& camera_i, const CameraModel& camera_j,
                                const std::vector<Correspondence>& matches,
                                const RelativePose& start,
                                const EssentialRefinementOptions& options = {});

}  // namespace silnet::aggregator
