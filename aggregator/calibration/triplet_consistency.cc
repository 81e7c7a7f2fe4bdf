#include "aggregator/calibration/triplet_consistency.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace silnet::aggregator {
namespace {

// Pixel -> centred coordinates in units of the half-diagonal.
Eigen::Matrix3d Normalisation(ViewSize size) {
  const double s = 0.5 * std::hypot(size.width, size.height);
  Eigen::Matrix3d t;
  t << 1.0 / s, 0.0, -0.5 * (size.width - 1) / s, 0.0, 1.0 / s, -0.5 * (size.height - 1) / s, 0.0,
      0.0, 1.0;
  return t;
}

// Unit right null vector of F.
Eigen::Vector3d RightNull(const Eigen::Matrix3d& F) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullV);
  return svd.matrixV().col(2);
}

// |q^T F p| / (|F p| |q|) for normalised F, p, q.
double Sine(const Eigen::Matrix3d& F, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d line = F * p;
  const double norm = line.norm() * q.norm();
  return norm > 0.0 ? std::abs(q.dot(line)) / norm : 1.0;
}

}  // namespace

double TripletInconsistency(const Eigen::Matrix3d& F_ab, const Eigen::Matrix3d& F_ac,
                            const Eigen::Matrix3d& F_bc, ViewSize a, ViewSize b, ViewSize c) {
  const Eigen::Matrix3d ta = Normalisation(a), tb = Normalisation(b), tc = Normalisation(c);
  // F' = T_to^-T F T_from^-1 maps normalised points to normalised lines.
  const Eigen::Matrix3d ab = tb.inverse().transpose() * F_ab * ta.inverse();
  const Eigen::Matrix3d ac = tc.inverse().transpose() * F_ac * ta.inverse();
  const Eigen::Matrix3d bc = tc.inverse().transpose() * F_bc * tb.inverse();
  const Eigen::Vector3d a_of_c = RightNull(ac), a_of_b = RightNull(ab), b_of_c = RightNull(bc);
  const Eigen::Vector3d b_of_a = RightNull(ab.transpose()), c_of_a = RightNull(ac.transpose()),
                        c_of_b = RightNull(bc.transpose());
  const double worst =
      std::max({Sine(ab, a_of_c, b_of_c), Sine(ac, a_of_b, c_of_b), Sine(bc, b_of_a, c_of_a)});
  const double scale = 0.5 * std::max({std::hypot(a.width, a.height), std::hypot(b.width, b.height),
                                       std::hypot(c.width, c.height)});
  return worst * scale;
}

}  // namespace silnet::aggregator
