#pragma once
// Calibration with known intrinsics (thesis 3.2.6 and 8.2.1): each link's essential matrix
// E = K_j^T F K_i gives the relative pose of its cameras (the decomposition whose
// triangulated frontier points lie in front of both); cameras are then chained like the
// projective reconstruction adds them: the first two through the strongest link (unit
// baseline), each next one through two links: its rotation the chordal mean of the two
// implied rotations, its centre the point closest to the two rays its relative translations
// give. A Euclidean bundle adjustment with the intrinsics held follows every addition.

#include <string>
#include <vector>

#include "aggregator/calibration/euclidean_bundle_adjustment.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the known-intrinsics chaining.
struct KnownIntrinsicsOptions {
  double min_ray_angle_deg = 2.0;  // the two rays placing a camera must be this far apart
  size_t tracks_per_link = 300;    // correspondences per link in the intermediate adjustments
  double max_added_rms_px = 5.0;   // a new camera fitting worse than this is rejected
  BundleOptions bundle;
};

// The chained network.
struct PoseChain {
  MetricScene scene;
  std::vector<std::string> added_by;
  std::vector<std::string> reasons;
  BundleSummary last_bundle;
};

// Places the cameras of `graph`; `cameras` carries each camera's K and distortion (and id,
// size, clock). Cameras that cannot be placed get a reason.
PoseChain ChainKnownIntrinsics(const ViewGraph& graph, const std::vector<CameraModel>& cameras,
                               const KnownIntrinsicsOptions& options, Progress* progress = nullptr);

}  // namespace silnet::aggregator
