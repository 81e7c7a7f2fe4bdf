#pragma once
// Calibration accuracy against ground truth (simulated captures): the estimated cameras are
// brought into the ground truth's frame by the similarity that best aligns the camera
// centres (Umeyama, proper rotations only), then focal lengths, rotations, centres and
// offsets are compared.

#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Errors of one camera.
struct CameraError {
  std::string id;
  double focal_rel = 0.0;      // |f - f_true| / f_true (mean of fx and fy)
  double rotation_deg = 0.0;   // angle of R_true^T R after alignment
  double center_rel = 0.0;     // |c - c_true| after alignment / rig diameter
  double principal_px = 0.0;   // |pp - pp_true|
  double k1_error = 0.0;       // |k1 - k1_true|
  double offset_frames = 0.0;  // |offset - offset_true| after removing the common shift
};

// Errors of a whole network (medians and maxima over the compared cameras).
struct CalibrationErrors {
  std::vector<CameraError> cameras;  // cameras present in both sets
  double rig_diameter = 0.0;         // largest distance between true centres
  double median_focal_rel = 0.0, max_focal_rel = 0.0;
  double median_rotation_deg = 0.0, max_rotation_deg = 0.0;
  double median_center_rel = 0.0, max_center_rel = 0.0;
  double median_offset_frames = 0.0, max_offset_frames = 0.0;
  double median_k1_error = 0.0;
};

// Compares the cameras of `estimated` that are `placed` with the same ids in `truth`.
// Needs at least 3 such cameras; throws InputError otherwise.
CalibrationErrors CompareWithGroundTruth(const std::vector<CameraModel>& estimated,
                                         const std::vector<bool>& placed,
                                         const std::vector<CameraModel>& truth);

// The cameras of `estimated` moved into the frame and scale of `truth` by the similarity
// that best aligns the centres of the cameras both have (the one CompareWithGroundTruth
// uses): what a reconstruction made with `estimated` needs to be scored against a true
// surface. Needs at least 3 common cameras; throws InputError otherwise.
std::vector<CameraModel> AlignedToGroundTruth(const std::vector<CameraModel>& estimated,
                                              const std::vector<CameraModel>& truth);

}  // namespace silnet::aggregator
