#pragma once
// A sphere seen by eight cameras on a ring, with exact silhouettes: the analytic scene of the
// hull tests.

#include <opencv2/core/mat.hpp>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator::hull_testing {

inline constexpr double kRingRadius = 4.5;  // camera distance D from the sphere centre, metres
inline constexpr double kRadius = 0.5;      // sphere radius r, metres
inline constexpr double kFocal = 686.0;     // pixels (50 degree horizontal field of view at 640 px)
inline constexpr int kCameras = 8;

// The sphere's centre, off the grid axes.
Eigen::Vector3d SphereCentre();

// Eight cameras every 45 degrees on a horizontal ring through the sphere centre, all
// looking at it; the ring is turned so no camera looks along a grid axis. With `generic`,
// heights and aim points vary by a few centimetres, which breaks the ring's mirror
// symmetries (exactly symmetric silhouettes make more than three cone faces meet at a point).
std::vector<CameraModel> RingCameras(double k1 = 0.0, bool generic = false);

// Exact silhouette: a pixel is set iff the ray through its centre meets the sphere.
cv::Mat SphereMask(const CameraModel& camera);
// The same for the sphere of `radius` about `centre`.
cv::Mat SphereMask(const CameraModel& camera, const Eigen::Vector3d& centre, double radius);

// Bound on |X - S| over the intersection of the cameras' cones (derivation in the source).
double ConeIntersectionRadius();
// The same for a sphere of `radius` seen from `distance` by `cameras` cameras evenly spaced
// on a ring through its centre with focal length `focal` pixels.
double ConeIntersectionRadius(double radius, double distance, double focal, int cameras);

// The ring cameras and their masks.
struct SphereScene {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
};
SphereScene MakeSphereScene(double k1 = 0.0, bool generic = false);

}  // namespace silnet::aggregator::hull_testing
