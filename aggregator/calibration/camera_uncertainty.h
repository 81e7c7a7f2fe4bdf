#pragma once
// Per-camera uncertainty of the final Euclidean bundle adjustment (never a confident wrong
// answer): the covariance of the camera parameters at the adjustment's solution, [J^T J]^-1
// of its own least-squares problem (ceres::Covariance, sparse QR over cameras and points,
// only the camera blocks recovered), scaled by the residual variance measured on the inlier
// observations, sum(r^2) / (residuals - parameters): the frontier points' noise is not known
// in advance, and each two-view point takes 3 of its 4 residuals' degrees of freedom.
//
// The adjustment fixes the similarity gauge by holding one camera's pose and another's
// distance from it, so those cameras would come out exact and the rest relative to them.
// The pose covariance is moved by an S-transformation (Triggs et al., "Bundle adjustment - a
// modern synthesis", 2000, section 9) into the gauge that aligns the camera centres best in
// the least-squares sense, the frame in which CompareWithGroundTruth measures errors (it
// aligns the centres by Umeyama). Intrinsics do not depend on the gauge. With held cameras
// (they define the frame) the covariance is taken as it is.
//
// Frontier points of neighbouring frames are not independent: the subject moves little from
// one frame to the next, so the tangents' errors repeat. With `frames_per_group` set, a
// delete-a-group jackknife is formed too: each group of consecutive frames is left out in
// turn, the solution moved by one Gauss-Newton step in the camera parameters (each track's
// point profiled out), and the spread of those moves taken as a covariance; every figure is
// the larger of the two estimates. A run without which some camera would not be held at all
// (one seen in those frames only) is not left out, so that camera keeps the independent
// figures. (The plain cluster-robust sandwich was tried first: where
// a group's points sit in one part of the volume, as a walking subject's do, it still
// reported 6x too little variance; the jackknife weighs such groups as they should.)
//
// The figures describe noise only: a model error (a principal point held at the image
// centre, distortion the model lacks) or a near-critical configuration the data barely
// settle can leave a camera further off than its deviations say.

#include <vector>

#include "aggregator/calibration/calibration_result.h"
#include "aggregator/calibration/euclidean_bundle_adjustment.h"

namespace silnet::aggregator {

// How the uncertainty treats the frontier points' errors.
struct UncertaintyOptions {
  // Frames taken together as one group whose errors may be correlated (grouped by the
  // track's first-view frame number); 0: every observation independent.
  int frames_per_group = 0;
};

// The uncertainty of every camera of `scene`, parallel to scene.cameras, as AdjustEuclidean
// left it with `model` and `options` (the same problem is built again). Cameras that are
// absent or have no inlier observation, and every camera when the covariance cannot be
// computed (a direction the data leave free), come back with estimated = false. `scene` is
// not changed; its units set those of nothing returned (centres are relative to the rig).
std::vector<CameraUncertainty> EstimateCameraUncertainty(
    const MetricScene& scene, const IntrinsicsModel& model, const BundleOptions& options,
    const UncertaintyOptions& uncertainty = {});

}  // namespace silnet::aggregator
