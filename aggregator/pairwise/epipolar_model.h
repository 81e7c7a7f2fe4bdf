#pragma once
// The epipolar geometry of a camera pair as the silhouette estimator parameterises it
// (thesis 2.3.2, A-1.2): the two epipoles and the epipolar line homography — the 1D
// projective map between the two pencils of epipolar lines — plus the pair's time offset.
//
// Lines through an epipole e form a pencil; with an orthonormal basis (u, v) of the plane
// orthogonal to e (as 3-vectors), a line l of the pencil has the 1D homogeneous coordinates
// (l.u, l.v). The homography h (2x2) maps the coordinates of a line in view i to those of
// the corresponding line in view j, and F = [u_j v_j] h [u_i v_i]^T [e_i]x.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>

namespace silnet::aggregator {

// An orthonormal basis (u, v) of the lines through a point e (homogeneous).
struct PencilBasis {
  Eigen::Vector3d e;  // unit length
  Eigen::Vector3d u;
  Eigen::Vector3d v;

  // The basis for `e`, with u built from the coordinate axis least aligned with e.
  static PencilBasis For(const Eigen::Vector3d& e);
  // 1D coordinates of a line through e.
  Eigen::Vector2d Coordinates(const Eigen::Vector3d& line) const {
    return {line.dot(u), line.dot(v)};
  }
  // The line with 1D coordinates c.
  Eigen::Vector3d Line(const Eigen::Vector2d& c) const { return c.x() * u + c.y() * v; }
};

// Epipoles, line homography and time offset of a camera pair.
struct EpipolarModel {
  PencilBasis pencil_i;
  PencilBasis pencil_j;
  Eigen::Matrix2d h = Eigen::Matrix2d::Identity();
  double offset = 0.0;  // frame k of i is simultaneous with frame k + offset of j

  // x_j^T F x_i = 0, scaled to unit Frobenius norm.
  Eigen::Matrix3d Fundamental() const;
  // The epipolar line in view j of a point of view i, and vice versa.
  Eigen::Vector3d LineInJ(const Eigen::Vector2d& x_i) const;
  Eigen::Vector3d LineInI(const Eigen::Vector2d& x_j) const;

  // The model of a rank-2 fundamental matrix (its null vectors as epipoles).
  static EpipolarModel FromFundamental(const Eigen::Matrix3d& f, double offset = 0.0);
};

// The minimal solver: the line homography from three corresponding epipolar lines
// (lines through e_i in view i, through e_j in view j). nullopt if the correspondences are
// degenerate (two lines of a view coincide).
std::optional<Eigen::Matrix2d> SolveLineHomography(const PencilBasis& pencil_i,
                                                   const PencilBasis& pencil_j,
                                                   const std::array<Eigen::Vector3d, 3>& lines_i,
                                                   const std::array<Eigen::Vector3d, 3>& lines_j);

// Symmetric epipolar transfer error of a correspondence, thesis eq. 2.1:
// d(x_j, F x_i) + d(x_i, F^T x_j), pixels.
double TransferError(const Eigen::Matrix3d& f, const Eigen::Vector2d& x_i,
                     const Eigen::Vector2d& x_j);

}  // namespace silnet::aggregator
