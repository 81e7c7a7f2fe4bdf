#include "aggregator/calibration/euclidean_bundle_adjustment.h"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>

#include "aggregator/calibration/projective_geometry.h"
#include "aggregator/calibration/reprojection_cost.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

// Intrinsics block: fx, fy, cx, cy, k1, k2, p1, p2, k3. Pose block: angle-axis, t.
constexpr int kIntrinsics = 9;
constexpr int kPose = 6;

// The principal point's deviation from the image centre, weighed as an observation:
// weight = observation sigma / prior sigma.
struct PrincipalPointPrior {
  Eigen::Vector2d centre;
  double weight;

  template <typename T>
  bool operator()(const T* k, T* residual) const {
    residual[0] = T(weight) * (k[2] - centre.x());
    residual[1] = T(weight) * (k[3] - centre.y());
    return true;
  }
};

using IntrinsicsBlock = Eigen::Matrix<double, kIntrinsics, 1>;
using PoseBlock = Eigen::Matrix<double, kPose, 1>;

IntrinsicsBlock ToBlock(const CameraModel& c) {
  IntrinsicsBlock b;
  b << c.K(0, 0), c.K(1, 1), c.K(0, 2), c.K(1, 2), c.dist[0], c.dist[1], c.dist[2], c.dist[3],
      c.dist[4];
  return b;
}

PoseBlock ToPose(const CameraModel& c) {
  const Eigen::AngleAxisd aa(c.R);
  PoseBlock b;
  b << aa.angle() * aa.axis(), c.t;
  return b;
}

void FromBlocks(const IntrinsicsBlock& k, const PoseBlock& pose, bool square, CameraModel* c) {
  c->K << k[0], 0.0, k[2], 0.0, square ? k[0] : k[1], k[3], 0.0, 0.0, 1.0;
  c->dist << k[4], k[5], k[6], k[7], k[8];
  const Eigen::Vector3d w = pose.head<3>();
  const double angle = w.norm();
  c->R = angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
  c->t = pose.tail<3>();
}

// Indices of the intrinsics block held constant under `model`.
std::vector<int> FixedIntrinsics(const IntrinsicsModel& model) {
  std::vector<int> fixed;
  if (model.square_pixels) fixed.push_back(1);
  if (model.fix_principal_point) {
    fixed.push_back(2);
    fixed.push_back(3);
  }
  if (model.radial_terms < 1) fixed.push_back(4);
  if (model.radial_terms < 2) fixed.push_back(5);
  for (int i : {6, 7, 8})
    fixed.push_back(i);
  return fixed;
}

// Moves the world frame onto the first observed camera (R = I, t = 0) and returns that
// camera and the observed camera furthest from it; the solve holds the first camera's pose
// and the second's distance from it, which removes the similarity gauge freedom.
std::pair<size_t, size_t> AnchorGauge(MetricScene* scene) {
  std::vector<bool> observed(scene->cameras.size(), false);
  for (size_t k = 0; k < scene->tracks.size(); ++k) {
    if (!scene->inlier[k]) continue;
    observed[scene->tracks[k].camera_a] = observed[scene->tracks[k].camera_b] = true;
  }
  const size_t n = scene->cameras.size();
  size_t anchor = n;
  for (size_t c = 0; c < n && anchor == n; ++c) {
    if (scene->present[c] && observed[c]) anchor = c;
  }
  if (anchor == n) return {n, n};
  const Eigen::Matrix3d r0 = scene->cameras[anchor].R;
  const Eigen::Vector3d t0 = scene->cameras[anchor].t;
  for (size_t c = 0; c < n; ++c) {
    if (!scene->present[c]) continue;
    CameraModel& camera = scene->cameras[c];
    camera.R = camera.R * r0.transpose();
    camera.t = camera.t - camera.R * t0;
  }
  for (Eigen::Vector3d& x : scene->points)
    x = r0 * x + t0;
  size_t scale = n;
  double furthest = 0.0;
  for (size_t c = 0; c < n; ++c) {
    if (c == anchor || !scene->present[c] || !observed[c]) continue;
    const double d = scene->cameras[c].t.norm();
    if (d > furthest) {
      furthest = d;
      scale = c;
    }
  }
  return {anchor, scale};
}

struct SolveOutcome {
  double initial_cost = 0.0;
  int iterations = 0;
  bool usable = false;
};

// Whether camera c's fy is tied to fx: intrinsics held as given keep their own fy.
bool SquarePixels(const IntrinsicsModel& model, const MetricScene& scene, size_t c) {
  return model.square_pixels && !model.fixed && !scene.Held(c);
}

}  // namespace

EuclideanProblem::EuclideanProblem() = default;
EuclideanProblem::~EuclideanProblem() = default;

std::unique_ptr<EuclideanProblem> BuildEuclideanProblem(MetricScene* scene,
                                                        const IntrinsicsModel& model,
                                                        const BundleOptions& options) {
  const size_t n = scene->cameras.size();
  bool any_held = false;
  for (size_t c = 0; c < n; ++c)
    any_held = any_held || (scene->present[c] && scene->Held(c));
  const auto [anchor, scale] = any_held ? std::pair{n, n} : AnchorGauge(scene);
  auto built = std::make_unique<EuclideanProblem>();
  std::vector<IntrinsicsBlock>& intrinsics = built->intrinsics;
  std::vector<PoseBlock>& poses = built->poses;
  intrinsics.resize(n);
  poses.resize(n);
  for (size_t c = 0; c < n; ++c) {
    if (!scene->present[c]) continue;
    intrinsics[c] = ToBlock(scene->cameras[c]);
    poses[c] = ToPose(scene->cameras[c]);
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  built->problem = std::make_unique<ceres::Problem>(problem_options);
  built->loss = std::make_unique<ceres::HuberLoss>(options.loss_px);
  ceres::Problem& problem = *built->problem;
  ceres::LossFunction* loss = built->loss.get();
  for (size_t k = 0; k < scene->tracks.size(); ++k) {
    if (!scene->inlier[k]) continue;
    const TwoViewTrack& t = scene->tracks[k];
    for (const auto& [camera, x] : {std::pair{t.camera_a, t.x_a}, std::pair{t.camera_b, t.x_b}}) {
      auto* cost = new ReprojectionCost(x, SquarePixels(model, *scene, camera));
      problem.AddResidualBlock(cost, loss, intrinsics[camera].data(), poses[camera].data(),
                               scene->points[k].data());
    }
  }
  if (model.principal_point_sigma_px > 0.0 && !model.fixed && !model.fix_principal_point) {
    for (size_t c = 0; c < n; ++c) {
      if (!scene->present[c] || !problem.HasParameterBlock(intrinsics[c].data())) continue;
      const CameraModel& camera = scene->cameras[c];
      const Eigen::Vector2d centre(0.5 * (camera.width - 1), 0.5 * (camera.height - 1));
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PrincipalPointPrior, 2, kIntrinsics>(
              new PrincipalPointPrior{centre,
                                      model.observation_sigma_px / model.principal_point_sigma_px}),
          nullptr, intrinsics[c].data());
    }
  }
  if (anchor < n) problem.SetParameterBlockConstant(poses[anchor].data());
  if (scale < n) {
    problem.SetManifold(
        poses[scale].data(),
        new ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::SphereManifold<3>>(
            ceres::EuclideanManifold<3>{}, ceres::SphereManifold<3>{}));
  }
  const std::vector<int> fixed = FixedIntrinsics(model);
  for (size_t c = 0; c < n; ++c) {
    if (!scene->present[c] || !problem.HasParameterBlock(intrinsics[c].data())) continue;
    if (scene->Held(c)) problem.SetParameterBlockConstant(poses[c].data());
    if (model.fixed || scene->Held(c)) {
      problem.SetParameterBlockConstant(intrinsics[c].data());
    } else {
      problem.SetManifold(intrinsics[c].data(), new ceres::SubsetManifold(kIntrinsics, fixed));
    }
  }
  return built;
}

namespace {

SolveOutcome Solve(MetricScene* scene, const IntrinsicsModel& model, const BundleOptions& options) {
  const size_t n = scene->cameras.size();
  const std::unique_ptr<EuclideanProblem> built = BuildEuclideanProblem(scene, model, options);
  ceres::Problem& problem = *built->problem;
  SolveOutcome outcome;
  if (problem.NumResidualBlocks() == 0) return outcome;
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.function_tolerance = options.function_tolerance;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  spdlog::debug("Euclidean bundle adjustment: {}", summary.BriefReport());
  for (size_t c = 0; c < n; ++c) {
    if (scene->present[c])
      FromBlocks(built->intrinsics[c], built->poses[c], SquarePixels(model, *scene, c),
                 &scene->cameras[c]);
  }
  outcome.initial_cost = summary.initial_cost;
  outcome.iterations = static_cast<int>(summary.iterations.size());
  outcome.usable = summary.termination_type != ceres::FAILURE && std::isfinite(summary.final_cost);
  return outcome;
}

}  // namespace

void MetricScene::Triangulate(double min_angle_deg) {
  points.resize(tracks.size());
  inlier.assign(tracks.size(), true);
  const double max_cos = std::cos(min_angle_deg * EIGEN_PI / 180.0);
  for (size_t k = 0; k < tracks.size(); ++k) {
    const TwoViewTrack& t = tracks[k];
    const CameraModel& a = cameras[t.camera_a];
    const CameraModel& b = cameras[t.camera_b];
    points[k] = TriangulateLinear(a.ProjectionMatrix(), b.ProjectionMatrix(),
                                  a.UndistortPixel(t.x_a), b.UndistortPixel(t.x_b))
                    .hnormalized();
    // Rays nearly parallel (or opposite) leave the point's depth undetermined.
    const Eigen::Vector3d ray_a = (a.R.transpose() * a.PixelRay(t.x_a)).normalized();
    const Eigen::Vector3d ray_b = (b.R.transpose() * b.PixelRay(t.x_b)).normalized();
    inlier[k] = std::abs(ray_a.dot(ray_b)) < max_cos;
  }
}

double MetricScene::ViewError(size_t track, int view) const {
  const TwoViewTrack& t = tracks[track];
  const CameraModel& c = cameras[view == 0 ? t.camera_a : t.camera_b];
  const auto projected = c.Project(points[track]);
  if (!projected) return 1e9;
  return (*projected - (view == 0 ? t.x_a : t.x_b)).norm();
}

BundleSummary AdjustEuclidean(MetricScene* scene, const IntrinsicsModel& model,
                              const BundleOptions& options, double outlier_px) {
  const auto start = std::chrono::steady_clock::now();
  BundleSummary summary;
  if (scene->points.size() != scene->tracks.size()) scene->Triangulate();
  if (scene->inlier.size() != scene->tracks.size())
    scene->inlier.assign(scene->tracks.size(), true);
  const auto track_error = [&](size_t k) {
    const double a = scene->ViewError(k, 0), b = scene->ViewError(k, 1);
    return std::sqrt(0.5 * (a * a + b * b));
  };
  // Sets aside tracks further off than max(outlier_px, `sigmas` robust deviations); returns
  // how many.
  const auto set_aside = [&](double sigmas) {
    std::vector<double> errors;
    for (size_t k = 0; k < scene->tracks.size(); ++k) {
      if (scene->inlier[k]) errors.push_back(track_error(k));
    }
    const double cut = std::max(outlier_px, sigmas * 1.4826 * UpperMedian(errors));
    size_t removed = 0;
    for (size_t k = 0; k < scene->tracks.size(); ++k) {
      if (scene->inlier[k] && !(track_error(k) <= cut)) {
        scene->inlier[k] = false;
        ++removed;
      }
    }
    return removed;
  };
  // Gross mismatches first (they slow the solver down), the rest after a first solve.
  set_aside(8.0);
  const SolveOutcome first = Solve(scene, model, options);
  summary.iterations = first.iterations;
  const size_t used =
      static_cast<size_t>(std::count(scene->inlier.begin(), scene->inlier.end(), true));
  summary.initial_rms_px =
      std::sqrt(first.initial_cost / std::max<double>(1.0, static_cast<double>(used)));
  const size_t removed = set_aside(4.0);
  SolveOutcome second = first;
  if (removed > 0) {
    second = Solve(scene, model, options);
    summary.iterations += second.iterations;
  }
  std::vector<double> errors;
  double sum2 = 0.0;
  for (size_t k = 0; k < scene->tracks.size(); ++k) {
    if (!scene->inlier[k]) continue;
    for (int view = 0; view < 2; ++view) {
      const double e = scene->ViewError(k, view);
      errors.push_back(e);
      sum2 += e * e;
    }
  }
  summary.observations = errors.size();
  summary.rms_px = errors.empty() ? 0.0 : std::sqrt(sum2 / static_cast<double>(errors.size()));
  summary.median_px = UpperMedian(std::move(errors));
  summary.usable = second.usable && summary.observations > 0;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace silnet::aggregator
