#pragma once
// What the network calibration produces (thesis chapter 3): the calibrated and synchronised
// cameras, the frontier points they were fitted to, what happened to each camera and each
// pairwise estimate, and figures for the report.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "aggregator/calibration/motion_coverage.h"
#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "aggregator/sync/network_sync.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// One observation of a frontier point: the camera (index into NetworkCalibration::cameras),
// the observed pixel (as measured, distortion included) and its reprojection error.
struct FrontierObservation {
  size_t camera = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double error_px = 0.0;
};

// A triangulated frontier point: a two-view correspondence of one camera pair (thesis 3.2:
// frontier points do not extend to more views), in world coordinates.
struct FrontierPoint {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();
  FrontierObservation views[2];
  uint64_t frame = 0;  // frame of the first view's camera
  bool inlier = true;  // false if the robust loss discarded it (error above the cut-off)
};

// How well the final Euclidean bundle adjustment determines one camera (camera_uncertainty.h):
// standard deviations from the adjustment's covariance, each the root of the summed variances
// of its components, i.e. the expected size of the error vector. Poses are taken in the gauge
// that aligns the camera centres best (as a comparison with ground truth aligns them).
struct CameraUncertainty {
  bool estimated = false;     // false: the covariance could not be computed
  double rotation_deg = 0.0;  // rotation, degrees
  double center_rel = 0.0;    // centre, relative to the rig diameter
  double focal_rel = 0.0;     // focal length, relative to itself
  double principal_px = 0.0;  // principal point, pixels
};

// What happened to one camera.
struct CameraPlacement {
  bool placed = false;
  std::string reason;       // why it was not placed; empty when placed
  std::string added_by;     // how: "initial triplet", "linked to cam01 and cam04", ...
  size_t observations = 0;  // frontier observations in the final bundle adjustment
  double rms_px = 0.0;      // reprojection error over its inlier observations
  double median_px = 0.0;
  CameraUncertainty uncertainty;  // from the final bundle adjustment, when placed
};

// A pairwise estimate checked against the final cameras (closing the loop).
struct PairCheck {
  size_t i = 0, j = 0;
  PairStatus pairwise_status = PairStatus::kFailed;
  std::string pairwise_reason;
  bool used = false;  // the calibration used this pair's correspondences
  Eigen::Matrix3d F_derived = Eigen::Matrix3d::Zero();  // from the final cameras
  // How far the estimate's inlier correspondences lie from the derived epipolar lines
  // (median symmetric distance); -1 without an estimate.
  double distance_px = -1.0;
  bool corrected = false;  // the derived F replaces a wrong or missing estimate
  std::string note;        // what the check found, for the report
};

// One stage of the calibration, for the report and the log.
struct CalibrationStage {
  std::string name;  // "projective reconstruction", "self-calibration", ...
  double rms_px = 0.0;
  double seconds = 0.0;
  std::string detail;
};

// The calibrated, synchronised network.
struct NetworkCalibration {
  // Every input camera in input order: id, image size and fps always; K, dist, R, t (world
  // frame of the reconstruction, arbitrary similarity) and time_offset when placed.
  std::vector<CameraModel> cameras;
  std::vector<CameraPlacement> placement;  // parallel to cameras
  std::vector<FrontierPoint> points;
  SyncResult sync;
  std::vector<PairCheck> pairs;
  std::vector<CalibrationStage> stages;
  double rms_px = 0.0;  // final reprojection error over inlier observations
  double median_px = 0.0;
  bool known_intrinsics = false;  // intrinsics given by the user (thesis 8.2.1)
  // How much each camera's silhouettes moved, parallel to `cameras` (empty without
  // silhouettes); a camera without enough motion is not calibrated.
  std::vector<MotionCoverage> motion;

  size_t PlacedCount() const {
    size_t n = 0;
    for (const CameraPlacement& p : placement)
      n += p.placed ? 1 : 0;
    return n;
  }
  // Which cameras were placed, parallel to `cameras`.
  std::vector<bool> PlacedMask() const {
    std::vector<bool> placed;
    for (const CameraPlacement& p : placement)
      placed.push_back(p.placed);
    return placed;
  }
  // The placed cameras, in input order.
  std::vector<CameraModel> PlacedCameras() const {
    std::vector<CameraModel> out;
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (placement[c].placed) out.push_back(cameras[c]);
    }
    return out;
  }
};

}  // namespace silnet::aggregator
