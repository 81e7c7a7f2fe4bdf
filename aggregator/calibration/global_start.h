#pragma once
// A global start for calibration with known intrinsics (beyond the thesis's chaining, which
// needs two trusted links per camera): every candidate solution of every pair, ambiguous
// ones included, gives a relative pose through its essential matrix E = K_j^T F K_i. A
// RANSAC over random spanning trees with random candidates finds the absolute rotations that
// the most pairs agree with (rotation cycles close), which also picks each pair's candidate;
// the rotations are then averaged over the agreeing pairs (chordal means) and the camera
// centres solved from the pairs' translation directions at once (least squares on
// (c_j - c_i) x d_ij = 0). Cameras need two agreeing pairs to get a centre.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the global start.
struct GlobalStartOptions {
  double rotation_tolerance_deg = 3.0;    // a pair agrees when its rotation is this close
  double direction_tolerance_deg = 10.0;  // ... and its baseline direction this close
  size_t trials = 3000;                   // random spanning trees tried
  uint64_t seed = 1;
};

// The start: poses of the cameras it could place, and which candidate of each pair agreed.
struct GlobalStart {
  bool ok = false;
  std::string reason;  // why not, when !ok
  std::vector<bool> present;
  std::vector<Eigen::Matrix3d> R;  // cam_from_world rotations of present cameras
  std::vector<Eigen::Vector3d> C;  // centres of present cameras
  // Per pair: -1 unused (not usable or disagreeing), 0 the reported solution, k >= 1 the
  // pair's alternative k - 1.
  std::vector<int> candidate;
  std::vector<double> rotation_error_deg;  // per pair, of the used candidate (-1 if unused)
};

// Estimates the start from `pairs` (ok and ambiguous ones; cameras named by id in
// `cameras`, which carry K and image size; silhouettes already undistorted).
GlobalStart EstimateGlobalStart(const std::vector<CameraModel>& cameras,
                                const std::vector<PairwiseResult>& pairs,
                                const GlobalStartOptions& options = {});

}  // namespace silnet::aggregator
