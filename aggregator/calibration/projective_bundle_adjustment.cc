#include "aggregator/calibration/projective_bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>

#include "aggregator/calibration/projective_geometry.h"
#include "aggregator/calibration/projective_reprojection_cost.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

Eigen::Vector2d Normalize(const Eigen::Matrix3d& n, const Eigen::Vector2d& x) {
  return (n * x.homogeneous()).hnormalized();
}

double ViewError(const Matrix34d& p, const Eigen::Matrix3d& n, const Eigen::Vector4d& x,
                 const Eigen::Vector2d& observed) {
  const Eigen::Vector3d projected = p * x;
  return (projected.hnormalized() - Normalize(n, observed)).norm() / n(0, 0);
}

}  // namespace

void ProjectiveScene::Triangulate() {
  points.resize(tracks.size());
  for (size_t k = 0; k < tracks.size(); ++k) {
    const TwoViewTrack& t = tracks[k];
    points[k] = TriangulateLinear(cameras[t.camera_a], cameras[t.camera_b],
                                  Normalize(normalization[t.camera_a], t.x_a),
                                  Normalize(normalization[t.camera_b], t.x_b));
  }
}

double ProjectiveScene::TrackError(size_t track) const {
  const TwoViewTrack& t = tracks[track];
  const double a = ViewError(cameras[t.camera_a], normalization[t.camera_a], points[track], t.x_a);
  const double b = ViewError(cameras[t.camera_b], normalization[t.camera_b], points[track], t.x_b);
  return std::sqrt(0.5 * (a * a + b * b));
}

BundleSummary AdjustProjective(ProjectiveScene* scene, const BundleOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  BundleSummary summary;
  if (scene->points.size() != scene->tracks.size()) scene->Triangulate();
  // Row-major camera parameter blocks, each scaled to unit norm.
  std::vector<Eigen::Matrix<double, 12, 1>> blocks(scene->cameras.size());
  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (!scene->present[c]) continue;
    const Matrix34d p = scene->cameras[c] / scene->cameras[c].norm();
    for (int r = 0; r < 3; ++r)
      blocks[c].segment<4>(4 * r) = p.row(r).transpose();
  }
  for (Eigen::Vector4d& x : scene->points)
    x.normalize();

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::SphereManifold<12> camera_sphere;
  ceres::SphereManifold<4> point_sphere;
  ceres::HuberLoss loss(options.loss_px);
  for (size_t k = 0; k < scene->tracks.size(); ++k) {
    const TwoViewTrack& t = scene->tracks[k];
    for (const auto& [camera, x] : {std::pair{t.camera_a, t.x_a}, std::pair{t.camera_b, t.x_b}}) {
      const Eigen::Matrix3d& n = scene->normalization[camera];
      auto* cost = new ProjectiveReprojectionCost(Normalize(n, x), 1.0 / n(0, 0));
      problem.AddResidualBlock(cost, &loss, blocks[camera].data(), scene->points[k].data());
    }
    problem.SetManifold(scene->points[k].data(), &point_sphere);
  }
  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (scene->present[c] && problem.HasParameterBlock(blocks[c].data()))
      problem.SetManifold(blocks[c].data(), &camera_sphere);
  }
  summary.observations = 2 * scene->tracks.size();
  if (summary.observations == 0) return summary;

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.function_tolerance = 1e-9;
  ceres::Solver::Summary result;
  ceres::Solve(solver, &problem, &result);

  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (!scene->present[c]) continue;
    for (int r = 0; r < 3; ++r)
      scene->cameras[c].row(r) = blocks[c].segment<4>(4 * r).transpose();
  }
  std::vector<double> errors;
  errors.reserve(summary.observations);
  double sum2 = 0.0;
  for (size_t k = 0; k < scene->tracks.size(); ++k) {
    const TwoViewTrack& t = scene->tracks[k];
    for (const auto& [camera, x] : {std::pair{t.camera_a, t.x_a}, std::pair{t.camera_b, t.x_b}}) {
      const double e =
          ViewError(scene->cameras[camera], scene->normalization[camera], scene->points[k], x);
      errors.push_back(e);
      sum2 += e * e;
    }
  }
  const double n = static_cast<double>(summary.observations);
  summary.initial_rms_px = std::sqrt(2.0 * result.initial_cost / n);
  summary.rms_px = std::sqrt(sum2 / n);
  summary.median_px = UpperMedian(std::move(errors));
  summary.iterations = static_cast<int>(result.iterations.size());
  summary.usable = result.termination_type != ceres::FAILURE && std::isfinite(result.final_cost);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace silnet::aggregator
