#pragma once
// Reprojection-error histograms: one small histogram per placed camera of the errors of its
// inlier observations, in a grid in one image, all with the same bins so they compare at a
// glance; each titled with the camera's rms and median error.

#include <opencv2/core.hpp>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// The grid (up to 4 columns of cell_width x cell_height panels) as a BGR image. Errors
// beyond the bins' end (the 99th percentile of all errors, rounded up) fall in the last bin.
cv::Mat DrawErrorHistograms(const NetworkCalibration& calibration, int cell_width = 350,
                            int cell_height = 240);

}  // namespace silnet::aggregator
