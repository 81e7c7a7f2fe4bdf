#pragma once
// The HTML sections of the calibration report (calibration_report.h), each an HTML fragment
// with all text from the calibration escaped.

#include <string>

#include "aggregator/calibration/calibration_result.h"
#include "aggregator/calibration/ground_truth_comparison.h"

namespace silnet::aggregator {

// Cameras placed, final reprojection error, intrinsics, points, synchronisation and pairs
// in a few lines; the unplaced cameras with their reasons.
std::string SummarySection(const NetworkCalibration& calibration);

// One row per stage: name, rms (px), seconds, detail.
std::string StagesSection(const NetworkCalibration& calibration);

// One row per input camera: placement or reason, intrinsics, centre, time offset,
// observations and reprojection error.
std::string CamerasSection(const NetworkCalibration& calibration);

// One row per offset measurement: cameras, measured offset, sigma, residual, used or why
// rejected, failed cycles.
std::string SyncEdgesSection(const NetworkCalibration& calibration);

// One row per checked pair: pairwise status and reason, used, Zhang distance to the derived
// F, corrected, note.
std::string PairChecksSection(const NetworkCalibration& calibration);

// Medians and maxima, then one row per compared camera.
std::string GroundTruthSection(const CalibrationErrors& errors);

}  // namespace silnet::aggregator
