#pragma once
// Camera poses from calibrated links (thesis 3.2.6 and 8.2.1): a link's essential matrix
// E = K_j^T F K_i gives the relative pose of its cameras; a camera linked to two or more
// placed cameras gets the chordal mean of the rotations they imply and the centre nearest to
// the rays pointing from them towards it.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "aggregator/calibration/view_graph.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Pose of camera b relative to camera a: x_b = R x_a + t, |t| = 1.
struct RelativePose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

// The relative pose of cameras a -> b from their link's essential matrix: the decomposition
// with the link's frontier points in front of both cameras (at least half of them), refined
// on those points (RefineRelativePose). nullopt
// without a link, with fewer than 8 correspondences, or if no decomposition qualifies.
std::optional<RelativePose> PoseOfLink(const ViewGraph& graph,
                                       const std::vector<CameraModel>& cameras, size_t a, size_t b);

// The rotation nearest (Frobenius) to the mean of `rotations`.
Eigen::Matrix3d ChordalMean(const std::vector<Eigen::Matrix3d>& rotations);

// World direction from placed camera p towards camera k, from their relative pose.
Eigen::Vector3d RayTowards(const CameraModel& p, const RelativePose& p_to_k);

// The point nearest to the rays origins[r] + s directions[r] (least squares; directions of
// unit length, not all parallel).
Eigen::Vector3d NearestToRays(const std::vector<Eigen::Vector3d>& origins,
                              const std::vector<Eigen::Vector3d>& directions);

}  // namespace silnet::aggregator
