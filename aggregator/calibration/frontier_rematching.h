#pragma once
// Frontier correspondences recomputed from a calibration (guided matching across the whole
// network, beyond the thesis): with cameras known, every pair's epipolar geometry follows
// from them and its time offset from the synchronisation, so frontier points can be matched
// for every pair whose cameras are calibrated — also pairs the pairwise stage did not trust —
// and on silhouettes with the lens distortion removed. Bundle adjustment on these
// correspondences corrects the bias the distortion put into the pairwise estimates.

#include <vector>

#include "aggregator/calibration/view_graph.h"
#include "aggregator/pairwise/silhouette_sequence.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The sequence with every hull's vertices undistorted by `camera` (re-hulled; edges keep
// their clipped bit when both ends were on clipped edges). A copy when there is no distortion.
SilhouetteSequence UndistortSequence(const SilhouetteSequence& sequence, const CameraModel& camera);

// The frontier correspondences of cameras i and j under the calibrated cameras and the pair
// offset o_i - o_j, on sequences already undistorted (UndistortSequence); returned in raw
// (distorted) pixels of each view.
std::vector<Correspondence> RematchFrontierPoints(const SilhouetteSequence& undistorted_i,
                                                  const SilhouetteSequence& undistorted_j,
                                                  const CameraModel& camera_i,
                                                  const CameraModel& camera_j, double offset);

// The pixel of an undistorted pixel under the camera's distortion (inverse of UndistortPixel).
Eigen::Vector2d DistortPixel(const CameraModel& camera, const Eigen::Vector2d& undistorted);

}  // namespace silnet::aggregator
