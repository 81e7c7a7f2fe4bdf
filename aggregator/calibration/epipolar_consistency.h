#pragma once
// How well the silhouettes of some frames agree with a calibration: for every pair of
// calibrated cameras, the epipolar tangents of each frame's hull (thesis 2.3.1) under the
// fundamental matrix and time offset the calibration implies, and the median transfer error
// of the frontier correspondences they give (thesis eq. 2.1). A camera that moved after the
// calibration shows up as a jump of these medians on every pair it belongs to.

#include <string>
#include <vector>

#include "aggregator/pairwise/silhouette_sequence.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The residual of one camera pair over a window of frames.
struct PairResidual {
  size_t i = 0;  // indices into the calibration's cameras, i < j
  size_t j = 0;
  size_t matches = 0;       // frontier correspondences found
  double median_px = -1.0;  // median symmetric transfer error; -1 with too few matches

  bool measured() const { return median_px >= 0.0; }
};

// The residuals of every pair of `placed` cameras whose sequences are in `sequences`
// (matched by camera id), over every usable frame the sequences hold; pairs with fewer than
// `min_matches` correspondences are reported unmeasured. Each pair's time offset is taken
// from the cameras' clocks (at the middle of the window if their frame rates differ).
std::vector<PairResidual> MeasureEpipolarResiduals(const std::vector<CameraModel>& cameras,
                                                   const std::vector<bool>& placed,
                                                   const std::vector<SilhouetteSequence>& sequences,
                                                   size_t min_matches = 20);

// The sequence of `camera_id` among `sequences`, or null.
const SilhouetteSequence* FindSequence(const std::vector<SilhouetteSequence>& sequences,
                                       const std::string& camera_id);

}  // namespace silnet::aggregator
