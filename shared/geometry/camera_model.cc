#include "shared/geometry/camera_model.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>

#include "shared/util/check.h"

namespace silnet {

Matrix34d CameraModel::ProjectionMatrix() const {
  Matrix34d rt;
  rt.leftCols<3>() = R;
  rt.col(3) = t;
  return K * rt;
}

Eigen::Vector2d DistortNormalized(const Distortion& dist, const Eigen::Vector2d& n) {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Matrix2d DistortionJacobian(const Distortion& dist, const Eigen::Vector2d& n) {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double d_radial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
  Eigen::Matrix2d jacobian;
  jacobian(0, 0) = radial + 2.0 * x * x * d_radial + 2.0 * p1 * y + 6.0 * p2 * x;
  jacobian(0, 1) = 2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y;
  jacobian(1, 0) = jacobian(0, 1);
  jacobian(1, 1) = radial + 2.0 * y * y * d_radial + 6.0 * p1 * y + 2.0 * p2 * x;
  return jacobian;
}

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& n) const {
  return DistortNormalized(dist, n);
}

Eigen::Vector2d CameraModel::Undistort(const Eigen::Vector2d& distorted) const {
  if (!HasDistortion()) return distorted;
  Eigen::Vector2d n = distorted;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d residual = Distort(n) - distorted;
    const Eigen::Vector2d step = DistortionJacobian(dist, n).partialPivLu().solve(residual);
    n -= step;
    if (step.squaredNorm() < 1e-28) break;
  }
  return n;
}

std::optional<Eigen::Vector2d> CameraModel::ProjectCameraPoint(const Eigen::Vector3d& x_cam) const {
  if (x_cam.z() <= 0.0) return std::nullopt;
  const Eigen::Vector2d d = Distort(x_cam.head<2>() / x_cam.z());
  return Eigen::Vector2d(K(0, 0) * d.x() + K(0, 1) * d.y() + K(0, 2), K(1, 1) * d.y() + K(1, 2));
}

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& world) const {
  return ProjectCameraPoint(R * world + t);
}

Eigen::Vector2d CameraModel::UndistortPixel(const Eigen::Vector2d& pixel) const {
  if (!HasDistortion()) return pixel;
  const Eigen::Vector3d ray = PixelRay(pixel);
  return (K * ray).hnormalized();
}

Eigen::Vector3d CameraModel::PixelRay(const Eigen::Vector2d& pixel) const {
  const double y = (pixel.y() - K(1, 2)) / K(1, 1);
  const double x = (pixel.x() - K(0, 2) - K(0, 1) * y) / K(0, 0);
  return Undistort({x, y}).homogeneous();
}

bool CameraModel::InImage(const Eigen::Vector2d& pixel) const {
  return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() <= width - 0.5 &&
         pixel.y() <= height - 0.5;
}

Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                               const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = target - center;
  SILNET_CHECK_MSG(forward.norm() > 1e-12, "camera centre equals its target");
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x_unnormalized = z.cross(up);  // image right = forward x up
  SILNET_CHECK_MSG(x_unnormalized.norm() > 1e-9, "viewing direction parallel to up");
  const Eigen::Vector3d x = x_unnormalized.normalized();
  const Eigen::Vector3d y = z.cross(x);  // image down
  Eigen::Matrix3d r;
  r.row(0) = x.transpose();
  r.row(1) = y.transpose();
  r.row(2) = z.transpose();
  return r;
}

CameraModel CameraAtImageSize(const CameraModel& camera, int width, int height) {
  if (camera.width <= 0 || camera.height <= 0 || width <= 0 || height <= 0)
    throw InputError("image sizes must be positive");
  const double sx = static_cast<double>(width) / camera.width;
  const double sy = static_cast<double>(height) / camera.height;
  if (std::abs(sx / sy - 1.0) > 0.01) {
    throw InputError(fmt::format("{}x{} has another aspect ratio than the calibration's {}x{}",
                                 width, height, camera.width, camera.height));
  }
  CameraModel scaled = camera;
  scaled.width = width;
  scaled.height = height;
  // Pixel centres: x' + 0.5 = s (x + 0.5).
  scaled.K.row(0) *= sx;
  scaled.K.row(1) *= sy;
  scaled.K(0, 2) += 0.5 * (sx - 1.0);
  scaled.K(1, 2) += 0.5 * (sy - 1.0);
  return scaled;
}

}  // namespace silnet
