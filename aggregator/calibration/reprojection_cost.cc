#include "aggregator/calibration/reprojection_cost.h"

#include <Eigen/Geometry>
#include <cmath>

#include "shared/geometry/camera_model.h"
#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

// R(w) and the right Jacobian of SO(3) at w: R(w + d) = R(w) Exp(J_r(w) d) to first order.
void RotationAndRightJacobian(const Eigen::Vector3d& w, Eigen::Matrix3d* rotation,
                              Eigen::Matrix3d* right_jacobian) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d wx = Skew(w);
  if (theta2 < 1e-12) {
    // Series to the order that matters at this size: R = I + [w]x + [w]x^2 / 2,
    // J_r = I - [w]x / 2 + [w]x^2 / 6.
    *rotation = Eigen::Matrix3d::Identity() + wx + 0.5 * wx * wx;
    *right_jacobian = Eigen::Matrix3d::Identity() - 0.5 * wx + wx * wx / 6.0;
    return;
  }
  const double theta = std::sqrt(theta2);
  *rotation = Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
  *right_jacobian = Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / theta2 * wx +
                    (theta - std::sin(theta)) / (theta2 * theta) * wx * wx;
}

}  // namespace

bool ReprojectionCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const double* k = parameters[0];
  const Eigen::Map<const Eigen::Vector3d> w(parameters[1]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[1] + 3);
  const Eigen::Map<const Eigen::Vector3d> world(parameters[2]);
  Eigen::Matrix3d rotation, right_jacobian;
  RotationAndRightJacobian(w, &rotation, &right_jacobian);
  const Eigen::Vector3d x = rotation * world + t;
  if (x.z() == 0.0) return false;
  const Eigen::Vector2d n = x.head<2>() / x.z();
  Distortion dist;
  dist << k[4], k[5], k[6], k[7], k[8];
  const Eigen::Vector2d d = DistortNormalized(dist, n);
  const double fx = k[0], fy = square_pixels_ ? k[0] : k[1];
  residuals[0] = fx * d.x() + k[2] - observed_.x();
  residuals[1] = fy * d.y() + k[3] - observed_.y();
  if (jacobians == nullptr) return true;

  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 9, Eigen::RowMajor>> j(jacobians[0]);
    const double r2 = n.squaredNorm();
    const double xy2 = 2.0 * n.x() * n.y();
    j.setZero();
    j(0, 0) = d.x();
    j(1, square_pixels_ ? 0 : 1) = d.y();  // with square pixels fy is fx
    j(0, 2) = 1.0;
    j(1, 3) = 1.0;
    // k1, k2, k3 scale the radial term; p1, p2 the tangential ones.
    j(0, 4) = fx * n.x() * r2;
    j(1, 4) = fy * n.y() * r2;
    j(0, 5) = j(0, 4) * r2;
    j(1, 5) = j(1, 4) * r2;
    j(0, 8) = j(0, 5) * r2;
    j(1, 8) = j(1, 5) * r2;
    j(0, 6) = fx * xy2;
    j(1, 6) = fy * (r2 + 2.0 * n.y() * n.y());
    j(0, 7) = fx * (r2 + 2.0 * n.x() * n.x());
    j(1, 7) = fy * xy2;
  }
  if (jacobians[1] == nullptr && jacobians[2] == nullptr) return true;
  // d pixel / d x_cam = diag(fx, fy) * d distort / d n * d n / d x_cam.
  Eigen::Matrix<double, 2, 3> dn_dx;
  const double inv_z = 1.0 / x.z();
  dn_dx << inv_z, 0.0, -n.x() * inv_z, 0.0, inv_z, -n.y() * inv_z;
  Eigen::Matrix<double, 2, 3> dpixel_dx = DistortionJacobian(dist, n) * dn_dx;
  dpixel_dx.row(0) *= fx;
  dpixel_dx.row(1) *= fy;
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> j(jacobians[1]);
    j.leftCols<3>() = -dpixel_dx * rotation * Skew(world) * right_jacobian;
    j.rightCols<3>() = dpixel_dx;
  }
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jacobians[2]);
    j = dpixel_dx * rotation;
  }
  return true;
}

}  // namespace silnet::aggregator
