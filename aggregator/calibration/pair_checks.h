#pragma once
// Closing the loop (thesis 3.2.6, Fig. 3.4): every pairwise estimate compared with the
// fundamental matrix the final cameras imply, so the report can say which estimates the
// network calibration corrected and which missing ones it supplies.

#include <vector>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// One check per pairwise result whose cameras are both in `cameras` (matched by id).
// Estimates whose inlier correspondences lie further than `corrected_px` (median) from the
// derived epipolar lines count as corrected. `used[p]` says whether pair p's correspondences
// entered the calibration.
std::vector<PairCheck> CheckPairs(const std::vector<CameraModel>& cameras,
                                  const std::vector<CameraPlacement>& placement,
                                  const std::vector<PairwiseResult>& pairs,
                                  const std::vector<bool>& used, double corrected_px);

}  // namespace silnet::aggregator
