#pragma once
// Rotations read from files that print them to a few decimals.

#include <Eigen/Core>
#include <optional>

namespace silnet {

// The rotation nearest to `r` (Frobenius norm, by SVD) if `r` is finite and within
// `tolerance` of it in every element and that rotation is proper (determinant +1); nullopt
// otherwise (a mirror, a scaled or sheared matrix, a typo).
std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& r, double tolerance);

}  // namespace silnet
