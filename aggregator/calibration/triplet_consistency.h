#pragma once
// Consistency of three fundamental matrices (thesis 3.2.2; Hartley & Zisserman 15.4): the
// image of each camera centre in the two other views is a correspondence of their pair, so
// for cameras a, b, c with e_a^c the epipole of c in view a,
//   (e_b^c)^T F_ab e_a^c = 0,   (e_c^b)^T F_ac e_a^b = 0,   (e_c^a)^T F_bc e_b^a = 0.
// Fundamental matrices of real cameras satisfy all three; a wrong one of the three breaks
// them. Each residual is the sine of the angle between the point and the epipolar line's
// plane in image coordinates centred and scaled by the half-diagonal (so epipoles far outside
// the image or at infinity are measured too), times the half-diagonal: about the point's
// distance from the line in pixels when both lie near the image.

#include <Eigen/Core>

namespace silnet::aggregator {

// Image size of a view, for the normalisation.
struct ViewSize {
  int width = 0;
  int height = 0;
};

// The largest of the three residuals of F_ab, F_ac, F_bc (x_b^T F_ab x_a = 0, and so on),
// in pixel-equivalents of the largest half-diagonal.
double TripletInconsistency(const Eigen::Matrix3d& F_ab, const Eigen::Matrix3d& F_ac,
                            const Eigen::Matrix3d& F_bc, ViewSize a, ViewSize b, ViewSize c);

}  // namespace silnet::aggregator
