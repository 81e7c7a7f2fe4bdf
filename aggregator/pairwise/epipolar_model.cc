#include "aggregator/pairwise/epipolar_model.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>

#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
PencilBasis PencilBasis::For(const Eigen::Vector3d& point) {
  PencilBasis b;
  b.e = point.normalized();
  Eigen::Index axis = 0;
  b.e.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d a = Eigen::Vector3d::Unit(axis);
  b.u = a.cross(b.e).normalized();
  b.v = b.e.cross(b.u);
  return b;
}

Eigen::Matrix3d EpipolarModel::Fundamental() const {
  Eigen::Matrix<double, 3, 2> basis_j, basis_i;
  basis_j << pencil_j.u, pencil_j.v;
  basis_i << pencil_i.u, pencil_i.v;
  const Eigen::Matrix3d f = basis_j * h * basis_i.transpose() * Skew(pencil_i.e);
  return f / f.norm();
}

Eigen::Vector3d EpipolarModel::LineInJ(const Eigen::Vector2d& x_i) const {
  const Eigen::Vector3d line_i = pencil_i.e.cross(x_i.homogeneous());
  return pencil_j.Line(h * pencil_i.Coordinates(line_i));
}

Eigen::Vector3d EpipolarModel::LineInI(const Eigen::Vector2d& x_j) const {
  const Eigen::Vector3d line_j = pencil_j.e.cross(x_j.homogeneous());
  // h^-1 up to scale is the adjugate.
  Eigen::Matrix2d adjugate;
  adjugate << h(1, 1), -h(0, 1), -h(1, 0), h(0, 0);
  return pencil_i.Line(adjugate * pencil_j.Coordinates(line_j));
}

EpipolarModel EpipolarModel::FromFundamental(const Eigen::Matrix3d& f, double offset) {
  EpipolarModel model;
  model.pencil_i = PencilBasis::For(EpipoleInFirstView(f));
  model.pencil_j = PencilBasis::For(EpipoleInSecondView(f));
  // h maps coordinates of [e_i]x x to those of F x: take x = u_i and x = v_i directions.
  Eigen::Matrix<double, 3, 2> basis_j;
  basis_j << model.pencil_j.u, model.pencil_j.v;
  for (int c = 0; c < 2; ++c) {
    // A point whose epipolar line in i has coordinates (1, 0) or (0, 1): x = line x e_i.
    const Eigen::Vector3d line_i = c == 0 ? model.pencil_i.u : model.pencil_i.v;
    const Eigen::Vector3d x = line_i.cross(model.pencil_i.e);
    // [e_i]x x = e_i x (line x e_i) = line (e.e) - e (e.line) = line, as e is unit and e.line = 0.
    model.h.col(c) = basis_j.transpose() * (f * x);
  }
  model.offset = offset;
  return model;
}

std::optional<Eigen::Matrix2d> SolveLineHomography(const PencilBasis& pencil_i,
                                                   const PencilBasis& pencil_j,
                                                   const std::array<Eigen::Vector3d, 3>& lines_i,
                                                   const std::array<Eigen::Vector3d, 3>& lines_j) {
  Eigen::Matrix<double, 3, 4> a;
  std::array<Eigen::Vector2d, 3> ci, cj;
  for (int k = 0; k < 3; ++k) {
    ci[static_cast<size_t>(k)] = pencil_i.Coordinates(lines_i[static_cast<size_t>(k)]).normalized();
    cj[static_cast<size_t>(k)] = pencil_j.Coordinates(lines_j[static_cast<size_t>(k)]).normalized();
    const Eigen::Vector2d& c = ci[static_cast<size_t>(k)];
    const Eigen::Vector2d& d = cj[static_cast<size_t>(k)];
    // d x (h c) = 0 with h = [a b; c d] -> d0 (h c)_1 - d1 (h c)_0 = 0.
    a.row(k) << -d.y() * c.x(), -d.y() * c.y(), d.x() * c.x(), d.x() * c.y();
  }
  // Distinct lines in each view, or the system is degenerate.
  for (int p = 0; p < 3; ++p) {
    for (int q = p + 1; q < 3; ++q) {
      const auto cross2 = [](const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
        return std::abs(x.x() * y.y() - x.y() * y.x());
      };
      if (cross2(ci[static_cast<size_t>(p)], ci[static_cast<size_t>(q)]) < 1e-9 ||
          cross2(cj[static_cast<size_t>(p)], cj[static_cast<size_t>(q)]) < 1e-9) {
        return std::nullopt;
      }
    }
  }
  // The null vector of the 3x4 system: the 4D generalised cross product of its rows.
  Eigen::Vector4d n;
  for (int col = 0; col < 4; ++col) {
    Eigen::Matrix3d minor;
    int m = 0;
    for (int c = 0; c < 4; ++c) {
      if (c == col) continue;
      minor.col(m++) = a.col(c);
    }
    n[col] = ((col % 2 == 0) ? 1.0 : -1.0) * minor.determinant();
  }
  if (n.norm() < 1e-12) return std::nullopt;
  n.normalize();
  Eigen::Matrix2d h;
  h << n[0], n[1], n[2], n[3];
  if (std::abs(h.determinant()) < 1e-9) return std::nullopt;
  return h;
}

double TransferError(const Eigen::Matrix3d& f, const Eigen::Vector2d& x_i,
                     const Eigen::Vector2d& x_j) {
  return PointLineDistance(f * x_i.homogeneous(), x_j) +
         PointLineDistance(f.transpose() * x_j.homogeneous(), x_i);
}

}  // namespace silnet::aggregator
