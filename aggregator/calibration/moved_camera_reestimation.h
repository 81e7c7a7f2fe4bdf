#pragma once
// Re-estimating one camera that moved, with the rest of the network held as calibrated: the
// pairwise estimator (thesis chapter 2) on frames after the move, between the moved camera
// and every other calibrated one, with the time offset the calibration knows as a narrow
// prior (the camera's clock did not change); each pair's essential matrix gives the moved
// camera's pose relative to its partner (relative_pose.h), the partners' poses place it in
// the network's frame and scale (rotation: chordal mean; centre: nearest to the rays from
// the partners); a bundle adjustment of its pose alone on the pairs' frontier points ends
// it. The camera's intrinsics are kept: a bumped or re-aimed camera keeps its lens.

#include <string>
#include <vector>

#include "aggregator/calibration/euclidean_bundle_adjustment.h"
#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the re-estimate.
struct MovedCameraOptions {
  PairwiseOptions pair;             // the pairwise estimator (offset prior set per pair)
  double offset_prior_sigma = 0.5;  // frames
  size_t min_pairs = 2;             // pairs that must succeed
  double max_ray_miss_deg = 3.0;    // partners whose ray misses the centre further are dropped
  size_t tracks_per_link = 300;
  double max_rms_px = 2.0;  // a fit worse than this is refused
  BundleOptions bundle;
  int threads = 0;  // pairs estimated at once (0 = all cores)
};

// The outcome; `camera` is meaningful when ok.
struct MovedCameraEstimate {
  bool ok = false;
  std::string reason;  // why not, when not ok
  CameraModel camera;
  std::vector<PairwiseResult> pairs;  // the moved camera against each partner
  std::vector<std::string> partners;  // the cameras that placed it
  double rms_px = 0.0;                // reprojection error of the final adjustment
  size_t observations = 0;
  double seconds = 0.0;
};

// Re-estimates camera `moved` of `cameras` (all of them calibrated where `placed`) from
// `sequences`, which must hold frames taken after the move (matched by camera id).
MovedCameraEstimate ReestimateMovedCamera(const std::vector<CameraModel>& cameras,
                                          const std::vector<bool>& placed, size_t moved,
                                          const std::vector<SilhouetteSequence>& sequences,
                                          const MovedCameraOptions& options,
                                          Progress* progress = nullptr);

}  // namespace silnet::aggregator
