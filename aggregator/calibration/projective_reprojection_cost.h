#pragma once
// The projective bundle adjustment's residual with analytic derivatives: a homogeneous point
// X through a projective camera P (row-major 3x4), in normalised coordinates, minus the
// observation, scaled back to pixels. Hand-derived rather than automatic derivatives (Ceres
// jets 16 wide).

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace silnet::aggregator {

// Parameter blocks: P (12, row-major), X (4); two residuals ((P X)_xy / (P X)_z - observed)
// * pixels_per_unit. Evaluate returns false (no values) where (P X)_z is zero.
class ProjectiveReprojectionCost final : public ceres::SizedCostFunction<2, 12, 4> {
 public:
  ProjectiveReprojectionCost(const Eigen::Vector2d& observed, double pixels_per_unit)
      : observed_(observed), pixels_per_unit_(pixels_per_unit) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector2d observed_;  // normalised coordinates
  double pixels_per_unit_;
};

}  // namespace silnet::aggregator
