#include "aggregator/calibration/camera_uncertainty.h"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

namespace silnet::aggregator {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr double kDegrees = 180.0 / EIGEN_PI;

Eigen::Matrix3d Rotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  return angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
}

Eigen::Vector3d Log(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

// d(psi, C) / d(w, t) at the pose block (w, t): psi the rotation error on the right
// (R exp([psi]x)), C = -R^T t the centre, so dC = [C]x dpsi - R^T dt.
Matrix6d PoseJacobian(const Eigen::Matrix<double, 6, 1>& pose) {
  const Eigen::Vector3d w = pose.head<3>();
  const Eigen::Matrix3d r = Rotation(w);
  const Eigen::Vector3d centre = -r.transpose() * pose.tail<3>();
  Matrix6d j = Matrix6d::Zero();
  constexpr double kStep = 1e-6;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d step = kStep * Eigen::Vector3d::Unit(i);
    j.block<3, 1>(0, i) =
        (Log(r.transpose() * Rotation(w + step)) - Log(r.transpose() * Rotation(w - step))) /
        (2.0 * kStep);
  }
  j.block<3, 3>(3, 0) = Skew(centre) * j.block<3, 3>(0, 0);
  j.block<3, 3>(3, 3) = -r.transpose();
  return j;
}

// Moves a covariance of (psi, C) per camera into the gauge that aligns the centres best:
// P S P^T with P = I - G (G^T W G)^-1 G^T W, G the 7 similarity motions (translation,
// rotation, scale) and W weighing the centres (the rotations only slightly, so two cameras'
// baseline still fixes its own rotation).
Eigen::MatrixXd ToCentreGauge(const Eigen::MatrixXd& covariance,
                              const std::vector<Eigen::Vector3d>& centres, double diameter) {
  const Eigen::Index m = static_cast<Eigen::Index>(centres.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(6 * m, 7);
  Eigen::VectorXd w(6 * m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const Eigen::Vector3d& c = centres[static_cast<size_t>(k)];
    g.block<3, 3>(6 * k, 3) = -Eigen::Matrix3d::Identity();
    g.block<3, 3>(6 * k + 3, 0) = Eigen::Matrix3d::Identity();
    g.block<3, 3>(6 * k + 3, 3) = -Skew(c);
    g.block<3, 1>(6 * k + 3, 6) = c;
    w.segment<3>(6 * k).setConstant(1e-6 * diameter * diameter);
    w.segment<3>(6 * k + 3).setOnes();
  }
  const Eigen::MatrixXd gtw = g.transpose() * w.asDiagonal();
  const Eigen::MatrixXd p =
      Eigen::MatrixXd::Identity(6 * m, 6 * m) - g * (gtw * g).partialPivLu().solve(gtw);
  return p * covariance * p.transpose();
}

}  // namespace

std::vector<CameraUncertainty> EstimateCameraUncertainty(const MetricScene& scene,
                                                         const IntrinsicsModel& model,
                                                         const BundleOptions& options) {
  const size_t n = scene.cameras.size();
  std::vector<CameraUncertainty> out(n);
  MetricScene anchored = scene;
  const std::unique_ptr<EuclideanProblem> built = BuildEuclideanProblem(&anchored, model, options);
  ceres::Problem& problem = *built->problem;
  if (problem.NumResidualBlocks() == 0) return out;

  // The cameras in the problem, their blocks, and whether any holds the frame.
  std::vector<size_t> cameras;
  std::vector<const double*> poses, blocks;
  bool any_held = false;
  for (size_t c = 0; c < n; ++c) {
    if (!anchored.present[c] || !problem.HasParameterBlock(built->poses[c].data())) continue;
    cameras.push_back(c);
    poses.push_back(built->poses[c].data());
    blocks.push_back(built->poses[c].data());
    blocks.push_back(built->intrinsics[c].data());
    any_held = any_held || anchored.Held(c);
  }

  // Residual variance: squared inlier errors over the degrees of freedom left.
  double sum2 = 0.0;
  for (size_t k = 0; k < anchored.tracks.size(); ++k) {
    if (!anchored.inlier[k]) continue;
    for (int view = 0; view < 2; ++view)
      sum2 += std::pow(anchored.ViewError(k, view), 2);
  }
  std::vector<double*> parameters;
  problem.GetParameterBlocks(&parameters);
  int free = 0;
  for (double* p : parameters) {
    if (!problem.IsParameterBlockConstant(p)) free += problem.ParameterBlockTangentSize(p);
  }
  const int dof = problem.NumResiduals() - free;
  if (dof <= 0) return out;
  const double variance = sum2 / dof;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  covariance_options.num_threads = options.threads;
  ceres::Covariance covariance(covariance_options);
  if (!covariance.Compute(blocks, &problem)) {
    spdlog::warn("camera uncertainty: the bundle adjustment's covariance is rank deficient");
    return out;
  }
  const Eigen::Index m = static_cast<Eigen::Index>(cameras.size());
  RowMajorMatrix pose_covariance(6 * m, 6 * m);
  if (!covariance.GetCovarianceMatrix(poses, pose_covariance.data())) return out;

  // Poses as (rotation error, centre), in the centre-aligned gauge.
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(6 * m, 6 * m);
  std::vector<Eigen::Vector3d> centres;
  double diameter = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) {
    const size_t c = cameras[static_cast<size_t>(k)];
    jacobian.block<6, 6>(6 * k, 6 * k) = PoseJacobian(built->poses[c]);
    centres.push_back(anchored.cameras[c].Center());
    for (const Eigen::Vector3d& other : centres)
      diameter = std::max(diameter, (other - centres.back()).norm());
  }
  Eigen::MatrixXd pose_sigma = jacobian * pose_covariance * jacobian.transpose();
  if (!any_held && diameter > 0.0) pose_sigma = ToCentreGauge(pose_sigma, centres, diameter);
  pose_sigma *= variance;

  for (Eigen::Index k = 0; k < m; ++k) {
    const size_t c = cameras[static_cast<size_t>(k)];
    Eigen::Matrix<double, 9, 9, Eigen::RowMajor> intrinsics;
    if (!covariance.GetCovarianceBlock(built->intrinsics[c].data(), built->intrinsics[c].data(),
                                       intrinsics.data()))
      continue;
    intrinsics *= variance;
    CameraUncertainty& u = out[c];
    u.estimated = true;
    u.rotation_deg = kDegrees * std::sqrt(pose_sigma.block<3, 3>(6 * k, 6 * k).trace());
    u.center_rel = diameter > 0.0
                       ? std::sqrt(pose_sigma.block<3, 3>(6 * k + 3, 6 * k + 3).trace()) / diameter
                       : 0.0;
    u.focal_rel = std::sqrt(intrinsics(0, 0)) / anchored.cameras[c].K(0, 0);
    u.principal_px = std::sqrt(intrinsics(2, 2) + intrinsics(3, 3));
  }
  return out;
}

}  // namespace silnet::aggregator
