#include "aggregator/calibration/projective_reprojection_cost.h"

namespace silnet::aggregator {

bool ProjectiveReprojectionCost::Evaluate(double const* const* parameters, double* residuals,
                                          double** jacobians) const {
  const Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> p(parameters[0]);
  const Eigen::Map<const Eigen::Vector4d> x(parameters[1]);
  const Eigen::Vector3d projected = p * x;
  if (projected.z() == 0.0) return false;
  const double inv_z = 1.0 / projected.z();
  const double u = projected.x() * inv_z, v = projected.y() * inv_z;
  residuals[0] = (u - observed_.x()) * pixels_per_unit_;
  residuals[1] = (v - observed_.y()) * pixels_per_unit_;
  if (jacobians == nullptr) return true;
  // d u / d (P X) = (1, 0, -u) / z and d v / d (P X) = (0, 1, -v) / z, times the scale.
  const double s = pixels_per_unit_ * inv_z;
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 12, Eigen::RowMajor>> j(jacobians[0]);
    j.setZero();
    j.block<1, 4>(0, 0) = s * x.transpose();
    j.block<1, 4>(0, 8) = -s * u * x.transpose();
    j.block<1, 4>(1, 4) = s * x.transpose();
    j.block<1, 4>(1, 8) = -s * v * x.transpose();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 4, Eigen::RowMajor>> j(jacobians[1]);
    j.row(0) = s * (p.row(0) - u * p.row(2));
    j.row(1) = s * (p.row(1) - v * p.row(2));
  }
  return true;
}

}  // namespace silnet::aggregator
