#pragma once
// The residual of the epipolar refinement (thesis 2.3.4) with analytic derivatives: the signed
// distances d(x_j, F x_i) and d(x_i, F^T x_j) of one frontier correspondence in the
// estimator's own parameters (epipoles e_i, e_j, line homography h, time offset). The pencil
// bases follow the epipoles from fixed reference axes: u = normalize(axis x e), v = e x u.
// Hand-derived rather than automatic derivatives (Ceres jets 11 wide), and each basis built
// once per evaluation of a solve (a per-thread memo of the last epipole), not per residual.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace silnet::aggregator {

// One frontier correspondence: x_i in frame i, and the outer-tangent points of the two
// frames of j around it, x_j_a and x_j_b, blended by the fraction time_i + offset.
struct TransferObservation {
  Eigen::Vector2d x_i, x_j_a, x_j_b;
  double time_i = 0.0;  // frame_i - frame_j: the blend fraction is time_i + offset
};

// Parameter blocks: e_i (3), e_j (3), h (4: h00, h01, h10, h11), offset (1); two residuals.
// Evaluate returns false (no values) where an epipolar line has no direction or a basis
// axis is parallel to its epipole.
class SymmetricTransferCost final : public ceres::SizedCostFunction<2, 3, 3, 4, 1> {
 public:
  SymmetricTransferCost(const TransferObservation& observation, const Eigen::Vector3d& axis_i,
                        const Eigen::Vector3d& axis_j)
      : observation_(observation), axis_i_(axis_i), axis_j_(axis_j) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  TransferObservation observation_;
  Eigen::Vector3d axis_i_, axis_j_;
};

}  // namespace silnet::aggregator
