#pragma once
// Small rotation helpers for posing articulated subjects.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace silnet::sim {

inline Eigen::Matrix3d RotationX(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
inline Eigen::Matrix3d RotationY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
inline Eigen::Matrix3d RotationZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// An orthonormal frame whose z axis is `along` and whose x axis is as close as possible
// to `forward` (used as a limb's texture frame).
inline Eigen::Matrix3d FrameAlong(const Eigen::Vector3d& along, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = along.normalized();
  Eigen::Vector3d x = forward - forward.dot(z) * z;
  if (x.norm() < 1e-6) x = z.unitOrthogonal();
  x.normalize();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = z.cross(x);
  frame.col(2) = z;
  return frame;
}

// Direction `from` turned by `angle` towards the part of `towards` orthogonal to it.
inline Eigen::Vector3d TurnTowards(const Eigen::Vector3d& from, const Eigen::Vector3d& towards,
                                   double angle) {
  Eigen::Vector3d perpendicular = towards - towards.dot(from) * from;
  if (perpendicular.norm() < 1e-9) return from;
  perpendicular.normalize();
  return std::cos(angle) * from + std::sin(angle) * perpendicular;
}

}  // namespace silnet::sim
