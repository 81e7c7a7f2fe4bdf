#pragma once
// Rotations read from files that print them to a few decimals.

#include <Eigen/Core>
#include <optional>

namespace silnet {

// How far, per element, a rotation read from a file may sit from a true rotation: enough for
// rotations printed to four decimals, far below any real error (a mirror or a typo).
inline constexpr double kPrintedRotationTolerance = 1e-4;

// The rotation nearest to `r` (Frobenius norm, by SVD) if `r` is finite and within
// `tolerance` of it in every element and that rotation is proper (determinant +1); nullopt
// otherwise (a mirror, a scaled or sheared matrix, a typo).
std::optional<Eigen::Matrix3d> NearestRotation(const Eigen::Matrix3d& r, double tolerance);

}  // namespace silnet
