#pragma once
// The Euclidean bundle adjustment's residual with analytic derivatives: the pixel of a world
// point through a camera with OpenCV's distortion, minus the observed pixel. Hand-derived
// rather than automatic derivatives (Ceres jets 18 wide were half of a 16-camera network's
// adjustment); the rotation's derivative through the right Jacobian of SO(3).

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace silnet::aggregator {

// Parameter blocks: intrinsics (fx, fy, cx, cy, k1, k2, p1, p2, k3), pose (angle-axis w and
// t: x_cam = R(w) X + t), the world point X; two residuals (pixels). With square pixels fy
// is fx (the block's fy is ignored and has zero derivative). Evaluate returns false (no
// values) for a point on the camera's principal plane.
class ReprojectionCost final : public ceres::SizedCostFunction<2, 9, 6, 3> {
 public:
  ReprojectionCost(const Eigen::Vector2d& observed, bool square_pixels)
      : observed_(observed), square_pixels_(square_pixels) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector2d observed_;
  bool square_pixels_;
};

}  // namespace silnet::aggregator
