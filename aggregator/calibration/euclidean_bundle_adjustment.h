#pragma once
// Euclidean bundle adjustment (thesis 3.2.5, B-2, and further): every camera's intrinsics
// (focal length, principal point, zero skew; optionally square pixels, a fixed principal
// point and radial distortion k1, k2 — the thesis left distortion out), pose (angle-axis and
// translation) and the frontier points in 3D, refined by Levenberg-Marquardt (Ceres, Schur
// complement, both cores) on the reprojection error in raw pixels under a Huber loss.
// Observations far off after a first solve are set aside and the problem solved again.

#include <memory>
#include <vector>

#include "aggregator/calibration/projective_bundle_adjustment.h"
#include "aggregator/calibration/two_view_tracks.h"
#include "shared/geometry/camera_model.h"

namespace ceres {
class LossFunction;
class Problem;
}  // namespace ceres

namespace silnet::aggregator {

// Which intrinsics the Euclidean bundle adjustment estimates.
struct IntrinsicsModel {
  bool square_pixels = true;         // fx = fy
  bool fix_principal_point = false;  // keep cx, cy as given
  // Prior on the principal point: a Gaussian about the image centre with this deviation
  // (pixels; 0 = none). Rings and domes of cameras that all look at the middle of the
  // capture area leave a common tilt of the cameras against a shift of their principal
  // points almost unobserved (a near-critical configuration for self-calibration); the prior
  // settles that direction and hardly moves the others.
  double principal_point_sigma_px = 0.0;
  double observation_sigma_px = 0.2;  // frontier point noise the prior is weighed against
  int radial_terms = 0;               // 0: none, 1: k1, 2: k1 and k2
  bool fixed = false;                 // intrinsics known (thesis 8.2.1): estimate poses only
};

// A metric reconstruction: cameras (absent ones ignored), tracks and their 3D points.
struct MetricScene {
  std::vector<bool> present;
  std::vector<CameraModel> cameras;
  std::vector<TwoViewTrack> tracks;
  std::vector<Eigen::Vector3d> points;  // one per track
  std::vector<bool> inlier;             // one per track
  // Cameras whose pose and intrinsics the adjustment keeps as they are (empty = none). When
  // any present camera is held, the held cameras fix the world frame and scale; otherwise
  // the adjustment anchors the gauge itself.
  std::vector<bool> held;

  bool Held(size_t camera) const { return camera < held.size() && held[camera]; }

  // Triangulates every track (undistorted pixels, linear) with the current cameras; tracks
  // whose two rays are within `min_angle_deg` of parallel or opposite are marked outliers.
  void Triangulate(double min_angle_deg = 3.0);
  // Reprojection error of view 0 (camera a) or 1 (camera b) of a track, pixels.
  double ViewError(size_t track, int view) const;
};

// The adjustment's least-squares problem over a scene, for solving it or for its covariance
// (camera_uncertainty.h): per present camera an intrinsics block (fx, fy, cx, cy, k1, k2, p1,
// p2, k3; pixels) and a pose block (angle-axis, t: x_cam = R·X + t), per inlier track its
// point in the scene's `points` (so the scene must outlive the problem).
struct EuclideanProblem {
  EuclideanProblem();
  ~EuclideanProblem();
  std::vector<Eigen::Matrix<double, 9, 1>> intrinsics;  // parallel to the scene's cameras
  std::vector<Eigen::Matrix<double, 6, 1>> poses;       // parallel to the scene's cameras
  std::unique_ptr<ceres::LossFunction> loss;            // the Huber loss of every observation
  std::unique_ptr<ceres::Problem> problem;
};

// Builds the problem on `scene` as AdjustEuclidean solves it. Without held cameras the gauge
// is anchored first: the world frame moves onto the first observed camera (its pose is held)
// and the observed camera furthest from it keeps its distance (its translation on a sphere).
std::unique_ptr<EuclideanProblem> BuildEuclideanProblem(MetricScene* scene,
                                                        const IntrinsicsModel& model,
                                                        const BundleOptions& options);

// Refines `scene` in place; tracks whose error exceeds max(outlier_px, 4 robust sigmas) after
// the first solve are marked outliers and left out of the second.
BundleSummary AdjustEuclidean(MetricScene* scene, const IntrinsicsModel& model,
                              const BundleOptions& options, double outlier_px = 2.0);

}  // namespace silnet::aggregator
