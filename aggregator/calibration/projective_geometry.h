#pragma once
// Projective two- and three-view geometry for the network calibration (thesis 3.2, HZ ch. 9,
// 15, 17): fundamental matrices of camera matrices, triangulation, image normalisation and
// the decomposition of a metric camera matrix.

#include <Eigen/Core>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// F with x_b^T F x_a = 0 for 3x4 cameras P_a, P_b, from 4x4 determinants of their rows
// (HZ 17.3). Bilinear in the rows of the two cameras, so it is affine in any rank-one change
// of P_b of the form e v^T; not normalised.
Eigen::Matrix3d FundamentalFromProjections(const Matrix34d& p_a, const Matrix34d& p_b);

// The centre of a finite or infinite camera: the unit null vector of P.
Eigen::Vector4d CameraCentre(const Matrix34d& p);

// Linear (DLT) triangulation of one correspondence, a unit homogeneous 4-vector.
Eigen::Vector4d TriangulateLinear(const Matrix34d& p_a, const Matrix34d& p_b,
                                  const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b);

// A camera's image normalisation N (x_n = N x): the image centre to the origin and pixels
// scaled by 1 / (width + height), so a normalised focal length of a typical lens is
// about 0.3 to 3 (Pollefeys et al.).
Eigen::Matrix3d ImageNormalization(int width, int height);

// K [R | t] from a finite camera P (up to scale and sign): K upper triangular with positive
// diagonal and K(2,2) = 1, R a rotation. Returns false if the left 3x3 block is singular.
bool DecomposeProjection(const Matrix34d& p, Eigen::Matrix3d* k, Eigen::Matrix3d* r,
                         Eigen::Vector3d* t);

}  // namespace silnet::aggregator
