#include "aggregator/pairwise/symmetric_transfer_cost.h"

#include <Eigen/Geometry>
#include <cmath>

#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

using Matrix3x11 = Eigen::Matrix<double, 3, 11>;
using Row11 = Eigen::Matrix<double, 1, 11>;
constexpr int kEi = 0, kEj = 3, kH = 6, kOffset = 10;  // columns of the stacked parameters

// A pencil basis u = normalize(axis x e), v = e x u and its derivatives by e.
struct Basis {
  Eigen::Vector3d u, v;
  Eigen::Matrix3d du, dv;
};

bool MakeBasis(const Eigen::Vector3d& e, const Eigen::Vector3d& axis, Basis* b) {
  const Eigen::Vector3d w = axis.cross(e);
  const double norm = w.norm();
  if (!(norm > 0.0)) return false;
  b->u = w / norm;
  b->v = e.cross(b->u);
  b->du = (Eigen::Matrix3d::Identity() - b->u * b->u.transpose()) / norm * Skew(axis);
  b->dv = Skew(e) * b->du - Skew(b->u);
  return true;
}

// MakeBasis, remembered per thread for the last epipole and axis: every residual of a solve
// is evaluated at the same parameters, so each basis is built once per evaluation. nullptr
// where MakeBasis fails; the basis stays valid until the thread's next call for `slot`.
const Basis* CachedBasis(const Eigen::Vector3d& e, const Eigen::Vector3d& axis, int slot) {
  struct Entry {
    Eigen::Vector3d e = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::Zero();
    Basis basis;
    bool valid = false;
  };
  thread_local Entry cache[2];
  Entry& entry = cache[slot];
  if (!entry.valid || entry.e != e || entry.axis != axis) {
    entry.valid = MakeBasis(e, axis, &entry.basis);
    entry.e = e;
    entry.axis = axis;
  }
  return entry.valid ? &entry.basis : nullptr;
}

// The signed distance of point x to line l (homogeneous, x with w = 1) and its derivatives
// from those of l and x.
bool LineDistance(const Eigen::Vector3d& l, const Matrix3x11& dl, const Eigen::Vector3d& x,
                  const Matrix3x11& dx, double* r, Row11* dr) {
  const double d2 = l.x() * l.x() + l.y() * l.y();
  if (!(d2 > 0.0)) return false;
  const double d = std::sqrt(d2);
  const double n = l.dot(x);
  *r = n / d;
  *dr = (x.transpose() * dl + l.transpose() * dx) / d -
        n / (d2 * d) * (l.x() * dl.row(0) + l.y() * dl.row(1));
  return true;
}

}  // namespace

bool SymmetricTransferCost::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> e_i(parameters[0]), e_j(parameters[1]);
  const double* h = parameters[2];
  const double f = observation_.time_i + parameters[3][0];
  const Basis* basis_i = CachedBasis(e_i, axis_i_, 0);
  const Basis* basis_j = CachedBasis(e_j, axis_j_, 1);
  if (basis_i == nullptr || basis_j == nullptr) return false;
  const Basis &bi = *basis_i, &bj = *basis_j;
  const TransferObservation& o = observation_;
  const Eigen::Vector3d xi = o.x_i.homogeneous();
  const Eigen::Vector3d xj = ((1.0 - f) * o.x_j_a + f * o.x_j_b).homogeneous();
  Matrix3x11 dxj = Matrix3x11::Zero();
  dxj.block<2, 1>(0, kOffset) = o.x_j_b - o.x_j_a;

  // Epipolar line in j of x_i: its pencil coordinates (c0, c1) in i mapped by h.
  const Eigen::Vector3d line_i = e_i.cross(xi);
  const Eigen::Matrix3d dline_i = -Skew(xi);
  const double c0 = line_i.dot(bi.u), c1 = line_i.dot(bi.v);
  const Eigen::RowVector3d dc0 = bi.u.transpose() * dline_i + line_i.transpose() * bi.du;
  const Eigen::RowVector3d dc1 = bi.v.transpose() * dline_i + line_i.transpose() * bi.dv;
  const double alpha = h[0] * c0 + h[1] * c1, beta = h[2] * c0 + h[3] * c1;
  const Eigen::Vector3d line_j = alpha * bj.u + beta * bj.v;
  Matrix3x11 dline_j = Matrix3x11::Zero();
  dline_j.block<3, 3>(0, kEi) = bj.u * (h[0] * dc0 + h[1] * dc1) + bj.v * (h[2] * dc0 + h[3] * dc1);
  dline_j.block<3, 3>(0, kEj) = alpha * bj.du + beta * bj.dv;
  dline_j.block<3, 4>(0, kH) << c0 * bj.u, c1 * bj.u, c0 * bj.v, c1 * bj.v;

  // Epipolar line in i of x_j, through the adjugate of h.
  const Eigen::Vector3d back_j = e_j.cross(xj);
  Matrix3x11 dback_j = Skew(e_j) * dxj;
  dback_j.block<3, 3>(0, kEj) = -Skew(xj);
  const double d0 = back_j.dot(bj.u), d1 = back_j.dot(bj.v);
  Row11 dd0 = bj.u.transpose() * dback_j, dd1 = bj.v.transpose() * dback_j;
  dd0.segment<3>(kEj) += back_j.transpose() * bj.du;
  dd1.segment<3>(kEj) += back_j.transpose() * bj.dv;
  const double gamma = h[3] * d0 - h[1] * d1, delta = -h[2] * d0 + h[0] * d1;
  const Eigen::Vector3d back_i = gamma * bi.u + delta * bi.v;
  Matrix3x11 dback_i = bi.u * (h[3] * dd0 - h[1] * dd1) + bi.v * (-h[2] * dd0 + h[0] * dd1);
  dback_i.block<3, 3>(0, kEi) += gamma * bi.du + delta * bi.dv;
  dback_i.block<3, 4>(0, kH) << d1 * bi.v, -d1 * bi.u, -d0 * bi.v, d0 * bi.u;

  Row11 dr0, dr1;
  if (!LineDistance(line_j, dline_j, xj, dxj, &residuals[0], &dr0) ||
      !LineDistance(back_i, dback_i, xi, Matrix3x11::Zero(), &residuals[1], &dr1)) {
    return false;
  }
  if (jacobians == nullptr) return true;
  const int starts[4] = {kEi, kEj, kH, kOffset}, sizes[4] = {3, 3, 4, 1};
  for (int block = 0; block < 4; ++block) {
    if (jacobians[block] == nullptr) continue;
    // Row-major 2 x size.
    for (int c = 0; c < sizes[block]; ++c) {
      jacobians[block][c] = dr0(starts[block] + c);
      jacobians[block][sizes[block] + c] = dr1(starts[block] + c);
    }
  }
  return true;
}

}  // namespace silnet::aggregator
