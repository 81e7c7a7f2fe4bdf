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

// The cameras of `estimated` moved into the frame and scale of `truth` (what a reconstruction
// made with them needs to be scored against a true surface) by the similarity that registers
// them at the subject, not at the camera centres (CompareWithGroundTruth's): the true cameras'
// pixels of `subject` points (a true surface, simulation only) triangulated with `estimated`
// land on those points as nearly as a similarity allows. The centres lie metres from the
// subject, so aligning them turns a tenth of a degree of rotation error into millimetres of
// misregistration there; this places what the estimated cameras reconstruct where the truth
// is, without looking at any reconstruction. Uses at most 5000 of the points; needs 3 common
// cameras and 100 points seen by two of them; throws InputError otherwise.
std::vector<CameraModel> AlignedAtSubject(const std::vector<CameraModel>& estimated,
                                          const std::vector<CameraModel>& truth,
                                          const std::vector<Eigen::Vector3d>& subject);

}  // namespace silnet::aggregator
