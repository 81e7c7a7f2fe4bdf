#pragma once
// Resolving a camera triplet (thesis 3.2.2): three projective cameras consistent with two
// trusted fundamental matrices F_12, F_13 and as close as possible to the third, F_23.
//
// With P_1 = [I | 0], P_2 = [[e_21]x F_12 | e_21] and P_3 = [[e_31]x F_13 | 0] + e_31 v^T, the
// cameras agree with F_12 and F_13 for any 4-vector v, and the F_23 they imply is affine in v.
// The thesis picks v by the Frobenius distance to the measured F_23; given F_23's frontier
// correspondences we pick it by their (Sampson-weighted) epipolar residuals instead, which
// measures what matters, and fall back to the Frobenius distance without them.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/view_graph.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Three consistent projective cameras.
struct TripletCameras {
  Matrix34d p1, p2, p3;
};

// Fundamental matrices of a triplet (x_b^T F_ab x_a = 0) and the correspondences of pair
// 2-3 (x_i in view 2, x_j in view 3), all in the same (normalised) image coordinates.
struct TripletInput {
  Eigen::Matrix3d f12, f13, f23;
  std::vector<Correspondence> matches23;
};

// The smallest angle, in radians, between the two epipoles of any view of the triplet: zero
// when the three camera centres are collinear (the degenerate case of 3.2.2).
double TripletEpipoleAngle(const Eigen::Matrix3d& f12, const Eigen::Matrix3d& f13,
                           const Eigen::Matrix3d& f23);

// Resolves the triplet. nullopt with a reason if the epipoles are degenerate.
std::optional<TripletCameras> ResolveTriplet(const TripletInput& input, std::string* why);

// The 4x4 projective transformation H with q_a H ~ p_a and q_b H ~ p_b (each up to its own
// scale): brings cameras reconstructed in the frame of (q_a, q_b) into the frame of (p_a, p_b).
Eigen::Matrix4d AlignProjectiveFrames(const Matrix34d& q_a, const Matrix34d& q_b,
                                      const Matrix34d& p_a, const Matrix34d& p_b);

}  // namespace silnet::aggregator
