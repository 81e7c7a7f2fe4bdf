#include "tests/aggregator/stereo/ball_scenes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/core.hpp>
#include <string>

#include "tests/aggregator/hulls/sphere_scene.h"

namespace silnet::aggregator::testing {

// Signed distance to the union of `balls` (exact outside it).
double UnionDistance(const std::vector<Ball>& balls, const Eigen::Vector3d& x) {
  double d = std::numeric_limits<double>::infinity();
  for (const Ball& b : balls)
    d = std::min(d, (x - b.centre).norm() - b.radius);
  return d;
}

// The union's outer surface point nearest to `x` (outside or on it) and the outward normal there.
std::pair<Eigen::Vector3d, Eigen::Vector3d> NearestSurface(const std::vector<Ball>& balls,
                                                           const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  std::pair<Eigen::Vector3d, Eigen::Vector3d> nearest;
  for (const Ball& b : balls) {
    const Eigen::Vector3d n = (x - b.centre).normalized();
    const Eigen::Vector3d p = b.centre + b.radius * n;
    if (UnionDistance(balls, p) < -1e-9) continue;  // inside another ball
    const double d = (x - p).norm();
    if (d < best) {
      best = d;
      nearest = {p, n};
    }
  }
  return nearest;
}

// Cameras 4.5 m from `target` at the given azimuths and elevations (degrees), 640x480, f 686 px.
std::vector<CameraModel> DomeCameras(const Eigen::Vector3d& target,
                                     const std::vector<std::pair<double, double>>& directions) {
  std::vector<CameraModel> cameras;
  for (const auto& [azimuth, elevation] : directions) {
    const double a = azimuth * std::numbers::pi / 180, e = elevation * std::numbers::pi / 180;
    CameraModel c;
    c.id = "cam" + std::to_string(cameras.size());
    c.width = 640;
    c.height = 480;
    c.K << 686, 0, 319.5, 0, 686, 239.5, 0, 0, 1;
    const Eigen::Vector3d centre =
        target +
        4.5 * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    c.R = LookAtRotation(centre, target, Eigen::Vector3d::UnitZ());
    c.t = -c.R * centre;
    cameras.push_back(c);
  }
  return cameras;
}

BallsHull HullOfBalls(const std::vector<Ball>& balls, const std::vector<CameraModel>& cameras) {
  BallsHull scene;
  scene.cameras = cameras;
  for (const CameraModel& camera : cameras) {
    cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8UC1);
    for (const Ball& b : balls)
      cv::bitwise_or(mask, hull_testing::SphereMask(camera, b.centre, b.radius), mask);
    scene.masks.push_back(mask);
  }
  PolyhedralHullOptions options;
  options.keep_provenance = true;
  scene.hull = ComputePolyhedralHull(cameras, scene.masks, options);
  return scene;
}

// Photo-consistency as a perfect matcher would see it: 1 on the surface, falling to -1 a
// centimetre away from it.
SegmentPhotoConsistency TruePhotoConsistency(const std::vector<Ball>& balls) {
  return [balls](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 50; ++k)
      nearest = std::min(nearest, std::abs(UnionDistance(balls, a + (b - a) * (k / 50.0))));
    return 2 * std::exp(-nearest / 0.01) - 1;
  };
}

std::vector<CameraModel> TenCameras(const Eigen::Vector3d& target) {
  return DomeCameras(target, {{0, 0},
                              {47, 5},
                              {95, -4},
                              {140, 2},
                              {187, 0},
                              {230, -6},
                              {275, 3},
                              {322, 1},
                              {20, 40},
                              {200, 35}});
}

}  // namespace silnet::aggregator::testing
