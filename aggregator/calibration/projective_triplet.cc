#include "aggregator/calibration/projective_triplet.h"

#include <Eigen/Dense>
#include <cmath>

#include "aggregator/calibration/projective_geometry.h"
#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

double AngleBetweenPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::min(1.0, c));
}

// v minimising the Sampson-weighted epipolar residuals of the pair 2-3 correspondences
// under F(v) = basis[0] + sum_k v_k basis[k + 1]; two reweighting passes.
std::optional<Eigen::Vector4d> SolveFromMatches(const std::array<Eigen::Matrix3d, 5>& basis,
                                                const std::vector<Correspondence>& matches) {
  if (matches.size() < 12) return std::nullopt;
  Eigen::Vector4d v = Eigen::Vector4d::Zero();
  std::vector<double> weights(matches.size(), 1.0);
  for (int pass = 0; pass < 3; ++pass) {
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
    for (size_t m = 0; m < matches.size(); ++m) {
      const Eigen::Vector3d x2 = matches[m].x_i.homogeneous(), x3 = matches[m].x_j.homogeneous();
      Eigen::Vector4d row;
      for (int k = 0; k < 4; ++k)
        row[k] = x3.dot(basis[k + 1] * x2);
      const double rhs = -x3.dot(basis[0] * x2);
      ata += weights[m] * row * row.transpose();
      atb += weights[m] * row * rhs;
    }
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(ata);
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    v = ldlt.solve(atb);
    if (!v.allFinite()) return std::nullopt;
    Eigen::Matrix3d f = basis[0];
    for (int k = 0; k < 4; ++k)
      f += v[k] * basis[k + 1];
    for (size_t m = 0; m < matches.size(); ++m) {
      const Eigen::Vector3d x2 = matches[m].x_i.homogeneous(), x3 = matches[m].x_j.homogeneous();
      const Eigen::Vector3d l3 = f * x2, l2 = f.transpose() * x3;
      const double g = l3.head<2>().squaredNorm() + l2.head<2>().squaredNorm();
      weights[m] = g > 1e-300 ? 1.0 / g : 0.0;
    }
  }
  return v;
}

// v minimising |F(v) - s F_23| in the Frobenius norm, both scaled to unit norm.
std::optional<Eigen::Vector4d> SolveFromFundamental(const std::array<Eigen::Matrix3d, 5>& basis,
                                                    const Eigen::Matrix3d& f23) {
  Eigen::Matrix<double, 9, 5> a;
  for (int k = 0; k < 4; ++k)
    a.col(k) = basis[k + 1].reshaped();
  a.col(4) = -f23.normalized().reshaped();
  const Eigen::Matrix<double, 9, 1> b = -basis[0].reshaped();
  const Eigen::Matrix<double, 5, 1> x = a.colPivHouseholderQr().solve(b);
  if (!x.allFinite() || std::abs(x[4]) < 1e-12) return std::nullopt;
  return Eigen::Vector4d(x.head<4>());
}

}  // namespace

double TripletEpipoleAngle(const Eigen::Matrix3d& f12, const Eigen::Matrix3d& f13,
                           const Eigen::Matrix3d& f23) {
  const double view1 = AngleBetweenPoints(EpipoleInFirstView(f12), EpipoleInFirstView(f13));
  const double view2 = AngleBetweenPoints(EpipoleInSecondView(f12), EpipoleInFirstView(f23));
  const double view3 = AngleBetweenPoints(EpipoleInSecondView(f13), EpipoleInSecondView(f23));
  return std::min({view1, view2, view3});
}

std::optional<TripletCameras> ResolveTriplet(const TripletInput& input, std::string* why) {
  const Eigen::Vector3d e21 = EpipoleInSecondView(input.f12);
  const Eigen::Vector3d e31 = EpipoleInSecondView(input.f13);
  TripletCameras t;
  t.p1.setZero();
  t.p1.leftCols<3>().setIdentity();
  t.p2 << Skew(e21) * input.f12, e21;
  Matrix34d p3_0;
  p3_0 << Skew(e31) * input.f13, Eigen::Vector3d::Zero();
  // F(v) is affine in v: its value at 0 and the changes along the unit vectors.
  std::array<Eigen::Matrix3d, 5> basis;
  basis[0] = FundamentalFromProjections(t.p2, p3_0);
  for (int k = 0; k < 4; ++k) {
    Matrix34d p3 = p3_0;
    p3.col(k) += e31;
    basis[k + 1] = FundamentalFromProjections(t.p2, p3) - basis[0];
  }
  std::optional<Eigen::Vector4d> v = SolveFromMatches(basis, input.matches23);
  if (!v) v = SolveFromFundamental(basis, input.f23);
  if (!v) {
    if (why) *why = "the third fundamental matrix is not reachable from the other two";
    return std::nullopt;
  }
  t.p3 = p3_0 + e31 * v->transpose();
  return t;
}

Eigen::Matrix4d AlignProjectiveFrames(const Matrix34d& q_a, const Matrix34d& q_b,
                                      const Matrix34d& p_a, const Matrix34d& p_b) {
  // Unknowns: the 16 entries of H (column-major) and the two scales; q H - s p = 0.
  Eigen::Matrix<double, 24, 18> a = Eigen::Matrix<double, 24, 18>::Zero();
  const Matrix34d* qs[2] = {&q_a, &q_b};
  const Matrix34d* ps[2] = {&p_a, &p_b};
  for (int c = 0; c < 2; ++c) {
    const Matrix34d q = *qs[c] / qs[c]->norm();
    const Matrix34d p = *ps[c] / ps[c]->norm();
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 4; ++col) {
        const int row = 12 * c + 4 * r + col;
        for (int k = 0; k < 4; ++k)
          a(row, 4 * col + k) = q(r, k);  // (q H)(r, col) = sum_k q(r, k) H(k, col)
        a(row, 16 + c) = -p(r, col);
      }
    }
  }
  Eigen::JacobiSVD<Eigen::Matrix<double, 24, 18>> svd(a, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 18, 1> x = svd.matrixV().col(17);
  Eigen::Matrix4d h;
  for (int col = 0; col < 4; ++col) {
    for (int k = 0; k < 4; ++k)
      h(k, col) = x[4 * col + k];
  }
  return h;
}

}  // namespace silnet::aggregator
