#include "aggregator/calibration/projective_geometry.h"

#include <Eigen/Dense>

namespace silnet::aggregator {
namespace {

// P without row `skip`, as a 2x4 block.
Eigen::Matrix<double, 2, 4> RowsWithout(const Matrix34d& p, int skip) {
  Eigen::Matrix<double, 2, 4> rows;
  int r = 0;
  for (int i = 0; i < 3; ++i) {
    if (i != skip) rows.row(r++) = p.row(i);
  }
  return rows;
}

}  // namespace

Eigen::Matrix3d FundamentalFromProjections(const Matrix34d& p_a, const Matrix34d& p_b) {
  Eigen::Matrix3d f;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Eigen::Matrix4d m;
      m.topRows<2>() = RowsWithout(p_a, i);
      m.bottomRows<2>() = RowsWithout(p_b, j);
      f(j, i) = ((i + j) % 2 == 0 ? 1.0 : -1.0) * m.determinant();
    }
  }
  return f;
}

Eigen::Vector4d CameraCentre(const Matrix34d& p) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.topRows<3>() = p;
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(m, Eigen::ComputeFullV);
  return svd.matrixV().col(3);
}

Eigen::Vector4d TriangulateLinear(const Matrix34d& p_a, const Matrix34d& p_b,
                                  const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b) {
  Eigen::Matrix4d a;
  a.row(0) = x_a.x() * p_a.row(2) - p_a.row(0);
  a.row(1) = x_a.y() * p_a.row(2) - p_a.row(1);
  a.row(2) = x_b.x() * p_b.row(2) - p_b.row(0);
  a.row(3) = x_b.y() * p_b.row(2) - p_b.row(1);
  for (int r = 0; r < 4; ++r)
    a.row(r).normalize();
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  return svd.matrixV().col(3);
}

Eigen::Matrix3d ImageNormalization(int width, int height) {
  const double scale = 1.0 / (width + height);
  Eigen::Matrix3d n;
  n << scale, 0.0, -0.5 * (width - 1) * scale, 0.0, scale, -0.5 * (height - 1) * scale, 0.0, 0.0,
      1.0;
  return n;
}

bool DecomposeProjection(const Matrix34d& p, Eigen::Matrix3d* k, Eigen::Matrix3d* r,
                         Eigen::Vector3d* t) {
  Eigen::Matrix3d m = p.leftCols<3>();
  Eigen::Vector3d p4 = p.col(3);
  const double det = m.determinant();
  if (!(std::abs(det) > 1e-300)) return false;
  if (det < 0.0) {
    m = -m;
    p4 = -p4;
  }
  // RQ decomposition of M through QR of the row-and-column-reversed transpose.
  Eigen::Matrix3d flip = Eigen::Matrix3d::Zero();
  flip(0, 2) = flip(1, 1) = flip(2, 0) = 1.0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * m).transpose());
  Eigen::Matrix3d q = qr.householderQ();
  Eigen::Matrix3d upper = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d kk = flip * upper.transpose() * flip;
  Eigen::Matrix3d rr = flip * q.transpose();
  // Positive diagonal of K: K D, D R with D = diag(+-1), D^2 = I.
  for (int i = 0; i < 3; ++i) {
    if (kk(i, i) < 0.0) {
      kk.col(i) = -kk.col(i);
      rr.row(i) = -rr.row(i);
    }
  }
  // det(M) > 0 and det(K) > 0 make R a proper rotation.
  const double scale = kk(2, 2);
  *k = kk / scale;
  *r = rr;
  *t = kk.inverse() * p4;
  return true;
}

}  // namespace silnet::aggregator
