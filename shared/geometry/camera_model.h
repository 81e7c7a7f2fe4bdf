#pragma once
// The one camera model every silnet job uses: pinhole intrinsics, OpenCV radial-tangential
// distortion, a cam_from_world pose, and the camera's clock (frame rate and time offset).
// Conventions in shared/geometry/conventions.h.

#include <Eigen/Core>
#include <optional>
#include <string>

namespace silnet {

// Distortion coefficients in OpenCV's order (k1, k2, p1, p2, k3).
using Distortion = Eigen::Matrix<double, 5, 1>;
using Matrix34d = Eigen::Matrix<double, 3, 4>;

// OpenCV's distortion of normalised coordinates (x/z, y/z) by coefficients `dist`.
Eigen::Vector2d DistortNormalized(const Distortion& dist, const Eigen::Vector2d& normalized);
// The derivative of DistortNormalized by the normalised coordinates, at `normalized`.
Eigen::Matrix2d DistortionJacobian(const Distortion& dist, const Eigen::Vector2d& normalized);

// A calibrated, clocked camera.
struct CameraModel {
  std::string id;
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Distortion dist = Distortion::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // cam_from_world rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // x_cam = R X + t
  double fps = 30.0;                                // frames per second
  double time_offset = 0.0;                         // frames; see conventions.h

  // Camera centre in world coordinates.
  Eigen::Vector3d Center() const { return -R.transpose() * t; }
  // P = K [R | t]; maps world points to undistorted pixels.
  Matrix34d ProjectionMatrix() const;
  bool HasDistortion() const { return !dist.isZero(0.0); }

  // Applies the distortion model to normalised coordinates (x/z, y/z).
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  // Inverts Distort by Newton iteration; exact to ~1e-12 inside the image.
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted) const;

  // Pixel of a point given in camera coordinates; nullopt if it is not in front (z <= 0).
  std::optional<Eigen::Vector2d> ProjectCameraPoint(const Eigen::Vector3d& x_cam) const;
  // Pixel of a world point (distortion applied); nullopt if behind the camera.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& world) const;
  // The pixel with distortion removed, in the same K (the input F and P work on).
  Eigen::Vector2d UndistortPixel(const Eigen::Vector2d& pixel) const;
  // Camera-frame direction (x, y, 1) of the ray through a (distorted) pixel.
  Eigen::Vector3d PixelRay(const Eigen::Vector2d& pixel) const;
  // True if a pixel lies on the image, [-0.5, width - 0.5] x [-0.5, height - 0.5].
  bool InImage(const Eigen::Vector2d& pixel) const;

  // Reference time in seconds at which (possibly fractional) frame `frame` was exposed.
  double ExposureTime(double frame) const { return (frame + time_offset) / fps; }
  // The (fractional) frame index exposed at reference time `seconds`.
  double FrameAt(double seconds) const { return seconds * fps - time_offset; }
};

// Rotation cam_from_world of a camera at `center` looking at `target`, with the image's
// "up" (-y) as close to `up` as possible. Throws CheckError if target == center or the
// viewing direction is parallel to `up`.
Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                               const Eigen::Vector3d& up);

// `camera` as it sees an image of `width` x `height` with the same field of view (a still
// taken at another resolution than the video): K scaled about the pixel-centre convention,
// x' + 0.5 = s (x + 0.5). Throws InputError if the aspect ratio differs by more than 1 %.
CameraModel CameraAtImageSize(const CameraModel& camera, int width, int height);

}  // namespace silnet
