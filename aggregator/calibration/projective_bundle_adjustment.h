#pragma once
// Projective bundle adjustment (thesis 3.2.5, B-2): camera matrices and homogeneous points
// refined together by Levenberg-Marquardt (Ceres, Schur complement) on the reprojection
// error, each camera and point on its own unit sphere (the projective scale gauge). Run
// after every camera the incremental reconstruction adds.

#include <vector>

#include "aggregator/calibration/two_view_tracks.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of a bundle adjustment.
struct BundleOptions {
  double loss_px = 1.0;  // Huber loss scale, pixels
  int max_iterations = 100;
  // Ceres threads. One by default: Ceres 2.1's Schur elimination locks a mutex per cell of the
  // reduced camera matrix for every point, and with the few cameras of a rig two threads made
  // the adjustments slower in wall time, not faster (docs/PERFORMANCE.md).
  int threads = 1;
  // Relative cost decrease below which the Euclidean adjustment stops. Ceres' default: at
  // 1e-7 the re-matched adjustments spent 60-70 of their ~75 iterations lowering the cost by
  // 1e-4 of itself along a direction the data barely hold, which moved the simulated
  // calibrations by 0.03 deg at most, either way (docs/PERFORMANCE.md).
  double function_tolerance = 1e-6;
};

// What a bundle adjustment achieved.
struct BundleSummary {
  double initial_rms_px = 0.0;
  double rms_px = 0.0;     // over all residuals after the solve
  double median_px = 0.0;  // median reprojection error of an observation
  size_t observations = 0;
  int iterations = 0;
  double seconds = 0.0;
  bool usable = false;  // the solver converged or stopped at the iteration limit with finite cost
};

// A projective reconstruction in normalised image coordinates (projective_geometry.h): the
// cameras (absent ones unset), their normalisations, and one homogeneous point per track.
struct ProjectiveScene {
  std::vector<bool> present;
  std::vector<Matrix34d> cameras;
  std::vector<Eigen::Matrix3d> normalization;  // pixels -> normalised coordinates
  std::vector<TwoViewTrack> tracks;            // raw pixels
  std::vector<Eigen::Vector4d> points;         // one per track

  // Triangulates every track linearly with the current cameras.
  void Triangulate();
  // Reprojection error of one track in pixels (RMS over its two views).
  double TrackError(size_t track) const;
};

// Refines cameras and points of `scene` in place.
BundleSummary AdjustProjective(ProjectiveScene* scene, const BundleOptions& options);

}  // namespace silnet::aggregator
