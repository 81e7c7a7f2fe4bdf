#pragma once
// Sanity gates on every calibrated camera (never a confident wrong answer): a calibration
// that fits its frontier points can still be wrong where the data leave it free (the
// near-critical configurations of self-calibration, a bundle adjustment drifting into a
// degenerate focal length). Each camera must have a focal length plausible for its image
// size, nearly square pixels, its principal point well inside the image, plausible radial
// distortion, its frontier points in front of it, and a rotation the final adjustment
// determines well (camera_uncertainty.h). A camera that fails is reported with the reason
// and not written as calibrated.

#include <string>
#include <vector>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// The limits of the gates.
struct CalibrationGates {
  double min_focal_factor = 0.2;      // focal length / larger image side, at least
  double max_focal_factor = 8.0;      // ... at most
  double max_aspect_error = 0.1;      // |fy / fx - 1|
  double max_principal_offset = 0.3;  // |pp - centre| / image size, per axis
  double max_abs_k1 = 1.5;            // |k1|
  double min_in_front = 0.95;         // share of a camera's frontier points in front of it
  // Rotation standard deviation (degrees) from the final adjustment, frames grouped as
  // CalibrationOptions::uncertainty says, at most; 0 = no limit. Measured: 0.15-0.25 on
  // simulated 8-camera rings (true errors 0.02-0.23), 1.4-3.9 on the real Utrecht capture
  // self-calibrated with k1, k2 (true errors 2.6-3.3 degrees against its own calibration;
  // 1.1-1.7 with every frontier point taken as independent, when the limit was 2.5;
  // docs/PERFORMANCE.md). The limit turns away cameras the data hardly hold without
  // rejecting that capture.
  double max_rotation_sigma_deg = 5.0;

  // A readable reason if the limits are unusable, empty if they are fine.
  std::string Validate() const;
};

// Why `camera` fails the gates, or empty if it passes; `in_front` is the share of its
// frontier observations in front of it.
std::string GateFailure(const CameraModel& camera, double in_front, const CalibrationGates& gates);

// Why a camera with `uncertainty` fails the uncertainty gate, or empty if it passes (or its
// uncertainty was not estimated).
std::string UncertaintyFailure(const CameraUncertainty& uncertainty, const CalibrationGates& gates);

// Applies the gates to every placed camera of `calibration`: a failing camera is marked not
// placed with the reason. Returns the number of cameras rejected.
size_t ApplyCalibrationGates(const CalibrationGates& gates, NetworkCalibration* calibration);

}  // namespace silnet::aggregator
