#include "aggregator/calibration/self_calibration.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>

namespace silnet::aggregator {
namespace {

// Index of Omega*'s entry (k, l), k <= l, in its 10 unknowns.
int QuadricIndex(int k, int l) {
  static constexpr std::array<std::array<int, 4>, 4> kIndex{
      {{0, 1, 2, 3}, {1, 4, 5, 6}, {2, 5, 7, 8}, {3, 6, 8, 9}}};
  return kIndex[static_cast<size_t>(k)][static_cast<size_t>(l)];
}

// Coefficients of omega*(a, b) = (P Omega* P^T)(a, b) in the 10 unknowns.
Eigen::Matrix<double, 1, 10> OmegaEntry(const Matrix34d& p, int a, int b) {
  Eigen::Matrix<double, 1, 10> row = Eigen::Matrix<double, 1, 10>::Zero();
  for (int k = 0; k < 4; ++k) {
    for (int l = 0; l < 4; ++l)
      row[QuadricIndex(std::min(k, l), std::max(k, l))] += p(a, k) * p(b, l);
  }
  return row;
}

Eigen::Matrix4d QuadricFromVector(const Eigen::Matrix<double, 10, 1>& q) {
  Eigen::Matrix4d omega;
  for (int k = 0; k < 4; ++k) {
    for (int l = 0; l < 4; ++l)
      omega(k, l) = q[QuadricIndex(std::min(k, l), std::max(k, l))];
  }
  return omega;
}

}  // namespace

std::optional<MetricUpgrade> SelfCalibrateLinear(const std::vector<Matrix34d>& cameras,
                                                 const std::vector<bool>& present,
                                                 std::string* why) {
  std::vector<Matrix34d> ps;
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (present[c]) ps.push_back(cameras[c] / cameras[c].norm());
  }
  if (ps.size() < 3) {
    if (why) *why = "self-calibration needs at least three cameras";
    return std::nullopt;
  }
  // Per camera: the current estimate of omega*(2, 2), the scale of its constraints.
  std::vector<double> nu(ps.size(), 1.0);
  Eigen::Matrix4d omega = Eigen::Matrix4d::Zero();
  for (int pass = 0; pass < 4; ++pass) {
    Eigen::MatrixXd a(6 * static_cast<Eigen::Index>(ps.size()), 10);
    for (size_t c = 0; c < ps.size(); ++c) {
      const Matrix34d& p = ps[c];
      const auto r = static_cast<Eigen::Index>(6 * c);
      const double v = nu[c];
      a.row(r + 0) = (OmegaEntry(p, 0, 0) - OmegaEntry(p, 2, 2)) / (9.0 * v);
      a.row(r + 1) = (OmegaEntry(p, 1, 1) - OmegaEntry(p, 2, 2)) / (9.0 * v);
      a.row(r + 2) = (OmegaEntry(p, 0, 0) - OmegaEntry(p, 1, 1)) / (0.2 * v);
      a.row(r + 3) = OmegaEntry(p, 0, 1) / (0.01 * v);
      a.row(r + 4) = OmegaEntry(p, 0, 2) / (0.1 * v);
      a.row(r + 5) = OmegaEntry(p, 1, 2) / (0.1 * v);
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
    omega = QuadricFromVector(svd.matrixV().col(9));
    // Omega* is positive semi-definite up to its arbitrary sign.
    double sign_votes = 0.0;
    for (const Matrix34d& p : ps)
      sign_votes += (p.row(2) * omega * p.row(2).transpose())(0, 0) > 0.0 ? 1.0 : -1.0;
    if (sign_votes < 0.0) omega = -omega;
    for (size_t c = 0; c < ps.size(); ++c) {
      const double w = (ps[c].row(2) * omega * ps[c].row(2).transpose())(0, 0);
      nu[c] = std::abs(w) > 1e-12 ? std::abs(w) : 1.0;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(omega);
  // Ascending eigenvalues: the smallest is dropped (rank 3), the other three must be positive.
  const Eigen::Vector4d values = eigen.eigenvalues();
  if (!(values[1] > 0.0)) {
    if (why) {
      *why =
          "the absolute dual quadric is not positive semi-definite (the projective "
          "reconstruction or the camera configuration does not allow self-calibration)";
    }
    return std::nullopt;
  }
  MetricUpgrade upgrade;
  const Eigen::Matrix4d v = eigen.eigenvectors();
  for (int k = 0; k < 3; ++k)
    upgrade.H.col(k) = v.col(k + 1) * std::sqrt(values[k + 1]);
  upgrade.H.col(3) = v.col(0);
  upgrade.omega = upgrade.H.leftCols<3>() * upgrade.H.leftCols<3>().transpose();
  return upgrade;
}

}  // namespace silnet::aggregator
