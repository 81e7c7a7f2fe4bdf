#pragma once
// Balls seen by calibrated cameras with exact silhouettes, and their exact hull with its
// provenance: the scenes of the tests of the exact silhouette constraints.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <utility>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/hull_two_colouring.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator::testing {

// A ball of the test scenes.
struct Ball {
  Eigen::Vector3d centre;
  double radius = 0;
};

// Signed distance to the union of `balls` (exact outside it).
double UnionDistance(const std::vector<Ball>& balls, const Eigen::Vector3d& x);

// The union's outer surface point nearest to `x` (outside or on it) and the outward normal there.
std::pair<Eigen::Vector3d, Eigen::Vector3d> NearestSurface(const std::vector<Ball>& balls,
                                                           const Eigen::Vector3d& x);

// Cameras 4.5 m from `target` at the given azimuths and elevations (degrees), 640x480, f 686 px.
std::vector<CameraModel> DomeCameras(const Eigen::Vector3d& target,
                                     const std::vector<std::pair<double, double>>& directions);

// Ten cameras around `target`, most near its height, two above it.
std::vector<CameraModel> TenCameras(const Eigen::Vector3d& target);

// The exact hull of `balls` seen by `cameras`, with its provenance, and the masks.
struct BallsHull {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  PolyhedralHullResult hull;
};
BallsHull HullOfBalls(const std::vector<Ball>& balls, const std::vector<CameraModel>& cameras);

// Photo-consistency as a perfect matcher would see it: 1 on the surface, falling to -1 a
// centimetre away from it.
SegmentPhotoConsistency TruePhotoConsistency(const std::vector<Ball>& balls);

}  // namespace silnet::aggregator::testing
