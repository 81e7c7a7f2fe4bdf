#include "tests/aggregator/hulls/sphere_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

namespace silnet::aggregator::hull_testing {

Eigen::Vector3d SphereCentre() {
  return {0.1, -0.05, 1.0};
}

// Eight cameras every 45 degrees on a horizontal ring through the sphere centre, all
// looking at it; the ring is turned so no camera looks along a grid axis.
std::vector<CameraModel> RingCameras(double k1, bool generic) {
  std::vector<CameraModel> cameras;
  for (int i = 0; i < kCameras; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kCameras + 0.1;
    CameraModel c;
    c.id = "ring" + std::to_string(i);
    c.width = 640;
    c.height = 480;
    c.K << kFocal, 0, 319.5, 0, kFocal, 239.5, 0, 0, 1;
    c.dist << k1, -0.25 * k1, 0, 0, 0;
    const double height = generic ? 0.04 * std::sin(1.7 * i + 0.3) : 0.0;
    const Eigen::Vector3d aim =
        generic ? Eigen::Vector3d(0.02 * std::cos(2.3 * i), 0.02 * std::sin(1.1 * i),
                                  0.02 * std::cos(0.7 * i))
                : Eigen::Vector3d::Zero();
    const Eigen::Vector3d centre =
        SphereCentre() + kRingRadius * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0) +
        Eigen::Vector3d(0, 0, height);
    c.R = LookAtRotation(centre, SphereCentre() + aim, Eigen::Vector3d::UnitZ());
    c.t = -c.R * centre;
    cameras.push_back(c);
  }
  return cameras;
}

// Exact silhouette: a pixel is set iff the ray through its centre meets the sphere.
cv::Mat SphereMask(const CameraModel& camera) {
  return SphereMask(camera, SphereCentre(), kRadius);
}

cv::Mat SphereMask(const CameraModel& camera, const Eigen::Vector3d& centre, double radius) {
  cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8UC1);
  const Eigen::Vector3d to_centre = camera.R * centre + camera.t;  // camera frame
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.PixelRay(Eigen::Vector2d(x, y)).normalized();
      if (ray.dot(to_centre) > 0 && ray.cross(to_centre).norm() <= radius) {
        mask.at<uint8_t>(y, x) = 255;
      }
    }
  }
  return mask;
}

// Bound on |X - S| over the intersection of the cameras' cones. A kept centre projects
// within half a pixel diagonal of a pixel centre whose ray meets the sphere, so it lies in
// the cone of half-angle a = asin(r / D) + atan(0.75 / f) about the camera's axis to S.
// Write X = S + v. For the camera whose axis d is closest to perpendicular to v's
// horizontal part (within 22.5 degrees, since cameras are every 45 degrees on a horizontal
// ring) |v . d| <= |v| sin(22.5), and the cone gives |v - (v.d) d| <= (D + v.d) tan(a).
// With c = cos(22.5), s = sin(22.5): |v| c <= (D + |v| s) tan(a), i.e.
// |v| <= D tan(a) / (c - s tan(a)). For D -> infinity this is r / cos(22.5): the octagon
// circumscribing the sphere's circle. With n cameras, 22.5 degrees becomes 180 / n.
double ConeIntersectionRadius() {
  return ConeIntersectionRadius(kRadius, kRingRadius, kFocal, kCameras);
}

double ConeIntersectionRadius(double radius, double distance, double focal, int cameras) {
  const double half_angle = std::asin(radius / distance) + std::atan(0.75 / focal);
  const double tan_a = std::tan(half_angle);
  const double c = std::cos(std::numbers::pi / cameras), s = std::sin(std::numbers::pi / cameras);
  return distance * tan_a / (c - s * tan_a);
}

SphereScene MakeSphereScene(double k1, bool generic) {
  SphereScene scene;
  scene.cameras = RingCameras(k1, generic);
  for (const CameraModel& c : scene.cameras)
    scene.masks.push_back(SphereMask(c));
  return scene;
}

}  // namespace silnet::aggregator::hull_testing
