#include "aggregator/calibration/essential_refinement.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>

namespace silnet::aggregator {
namespace {

// The Sampson distance of one correspondence under E = [t]x R, in pixels: the algebraic
// error b^T E a over its gradient with respect to both pixels (a, b normalised image
// points, z = 1; f_i, f_j the focal lengths that turn them into pixels).
struct SampsonDistance {
  Eigen::Vector3d a, b;
  double f_i = 1.0, f_j = 1.0;

  template <typename T>
  bool operator()(const T* rotation, const T* translation, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(rotation);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    const Eigen::Matrix<T, 3, 1> ea = t.cross(q * a.cast<T>());
    const Eigen::Matrix<T, 3, 1> bt = b.cast<T>().cross(t);
    const Eigen::Matrix<T, 3, 1> etb = q.conjugate() * bt;
    const T gradient = (ea.x() * ea.x() + ea.y() * ea.y()) / T(f_j * f_j) +
                       (etb.x() * etb.x() + etb.y() * etb.y()) / T(f_i * f_i);
    residual[0] = b.cast<T>().dot(ea) / ceres::sqrt(gradient + T(1e-300));
    return true;
  }
};

}  // namespace

RelativePose RefineRelativePose(const CameraModel& camera_i, const CameraModel& camera_j,
                                const std::vector<Correspondence>& matches,
                                const RelativePose& start,
                                const EssentialRefinementOptions& options) {
  if (matches.size() < 5) return start;
  Eigen::Quaterniond q(start.R);
  Eigen::Vector3d t = start.t.normalized();
  ceres::Problem problem;
  for (const Correspondence& m : matches) {
    const Eigen::Vector3d a = camera_i.PixelRay(m.x_i);  // (x, y, 1)
    const Eigen::Vector3d b = camera_j.PixelRay(m.x_j);
    if (!a.allFinite() || !b.allFinite()) continue;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SampsonDistance, 1, 4, 3>(
                                 new SampsonDistance{a, b, camera_i.K(0, 0), camera_j.K(0, 0)}),
                             new ceres::CauchyLoss(options.loss_px), q.coeffs().data(), t.data());
  }
  if (problem.NumResidualBlocks() < 5) return start;
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  problem.SetManifold(t.data(), new ceres::SphereManifold<3>);
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable() || !q.coeffs().allFinite() || !t.allFinite()) return start;
  return RelativePose{q.normalized().toRotationMatrix(), t.normalized()};
}

}  // namespace silnet::aggregator
