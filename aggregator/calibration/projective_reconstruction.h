#pragma once
// Incremental projective reconstruction of a camera network from its view graph (thesis
// 3.2.3-3.2.4): the best-scoring non-degenerate triplet is resolved first; then, one at a
// time, the camera with the strongest pair of links to the reconstruction is added by
// resolving the triplet it forms with those two cameras (whose F is now known exactly) and
// mapping it into the network's frame; a projective bundle adjustment follows every addition.

#include <string>
#include <vector>

#include "aggregator/calibration/projective_bundle_adjustment.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the projective stage.
struct ProjectiveOptions {
  double min_epipole_angle_deg = 2.0;  // triplets with closer epipoles count as collinear
  size_t tracks_per_link = 300;        // correspondences per link in the bundle adjustments
  double max_added_rms_px = 5.0;       // a new camera fitting worse than this is rejected
  BundleOptions bundle;
};

// The projective network and how it was built.
struct ProjectiveReconstruction {
  ProjectiveScene scene;
  std::vector<std::string> added_by;  // per camera: how it joined, empty if it did not
  std::vector<std::string> reasons;   // per camera: why it did not join
  BundleSummary last_bundle;
  size_t placed() const;
};

// Reconstructs the cameras of `graph`; `cameras` gives each camera's image size. Cameras
// that cannot be added get a reason. With no usable triplet nothing is placed and every
// camera gets the reason. Honours cancellation between additions.
ProjectiveReconstruction ReconstructProjective(const ViewGraph& graph,
                                               const std::vector<CameraModel>& cameras,
                                               const ProjectiveOptions& options,
                                               Progress* progress = nullptr);

}  // namespace silnet::aggregator
