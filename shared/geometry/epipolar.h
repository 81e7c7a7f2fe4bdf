#pragma once
// Two-view epipolar geometry on undistorted pixels (conventions.h): x_j^T F x_i = 0.

#include <Eigen/Core>

#include "shared/geometry/camera_model.h"

namespace silnet {

// The fundamental matrix F_ij of two cameras (ignoring their distortion), scaled to unit
// Frobenius norm. Points of camera i map to epipolar lines l_j = F x_i in camera j.
Eigen::Matrix3d FundamentalFromCameras(const CameraModel& camera_i, const CameraModel& camera_j);

// F scaled to unit Frobenius norm with a non-negative largest-magnitude entry, so equal
// matrices compare equal entry by entry.
Eigen::Matrix3d NormalizeFundamental(const Eigen::Matrix3d& f);

// The epipole in camera i (F e_i = 0) as a homogeneous unit vector.
Eigen::Vector3d EpipoleInFirstView(const Eigen::Matrix3d& f);
// The epipole in camera j (F^T e_j = 0) as a homogeneous unit vector.
Eigen::Vector3d EpipoleInSecondView(const Eigen::Matrix3d& f);

// The cross-product matrix of v: Skew(v) * w = v x w.
Eigen::Matrix3d Skew(const Eigen::Vector3d& v);

// Distance in pixels from point x to the homogeneous line l.
double PointLineDistance(const Eigen::Vector3d& line, const Eigen::Vector2d& x);

// Symmetric epipolar distance of a correspondence, the RMS of d(x_j, F x_i) and
// d(x_i, F^T x_j) in pixels.
double SymmetricEpipolarDistance(const Eigen::Matrix3d& f, const Eigen::Vector2d& x_i,
                                 const Eigen::Vector2d& x_j);

// How the clocks of two cameras relate: frame k of camera i is simultaneous with the
// (fractional) frame offset + rate * k of camera j.
struct PairTiming {
  double offset = 0.0;
  double rate = 1.0;
};

// The timing of a camera pair from each camera's fps and time offset (conventions.h).
PairTiming PairTimingFromCameras(const CameraModel& camera_i, const CameraModel& camera_j);

}  // namespace silnet
