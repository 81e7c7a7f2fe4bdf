#include "shared/geometry/nearest_rotation.h"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace silnet {

std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& r, double tolerance) {
  if (!r.allFinite()) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0.0 || !((r - rotation).cwiseAbs().maxCoeff() <= tolerance))
    return std::nullopt;
  return rotation;
}

}  // namespace silnet
