#pragma once
// Small queries on a NetworkCalibration shared by the report's plots and tables.

#include <string>
#include <vector>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// True if camera `index` exists and was placed.
bool IsPlaced(const NetworkCalibration& calibration, size_t index);

// The camera's id, or "#<index>" for an index without a camera.
std::string CameraLabel(const NetworkCalibration& calibration, size_t index);

// The reprojection errors (px) of the inlier observations of each camera, indexed like
// calibration.cameras; observations of unknown cameras are ignored.
std::vector<std::vector<double>> InlierErrorsPerCamera(const NetworkCalibration& calibration);

// Median and root mean square of `values`; 0 when empty.
double Median(std::vector<double> values);
double Rms(const std::vector<double>& values);

}  // namespace silnet::aggregator
