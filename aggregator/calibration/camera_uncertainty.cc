#include "aggregator/calibration/camera_uncertainty.h"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <map>
#include <unordered_map>

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

// The camera blocks of a problem (per camera its pose, then its intrinsics), with each
// block's place in the ambient and tangent coordinates of their joint covariance.
struct CameraBlocks {
  std::vector<size_t> cameras;  // the cameras in the problem
  std::vector<const double*> blocks;
  std::vector<int> ambient_offset, tangent_offset;
  int ambient = 0, tangent = 0;
  std::unordered_map<const double*, size_t> index;  // block -> position in `blocks`
};

CameraBlocks CollectCameraBlocks(const MetricScene& scene, const EuclideanProblem& built) {
  CameraBlocks b;
  const ceres::Problem& problem = *built.problem;
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    if (!scene.present[c] || !problem.HasParameterBlock(built.poses[c].data())) continue;
    b.cameras.push_back(c);
    for (const double* block : {built.poses[c].data(), built.intrinsics[c].data()}) {
      b.index[block] = b.blocks.size();
      b.blocks.push_back(block);
      b.ambient_offset.push_back(b.ambient);
      b.tangent_offset.push_back(b.tangent);
      b.ambient += problem.ParameterBlockSize(block);
      b.tangent += problem.ParameterBlockTangentSize(block);
    }
  }
  return b;
}

// d(ambient) / d(tangent) of every camera block at its value, block diagonal (zero for held
// blocks, which have no tangent direction the covariance knows).
Eigen::MatrixXd PlusJacobian(const ceres::Problem& problem, const CameraBlocks& b) {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(b.ambient, b.tangent);
  for (size_t k = 0; k < b.blocks.size(); ++k) {
    const double* block = b.blocks[k];
    if (problem.IsParameterBlockConstant(block)) continue;
    const int ambient = problem.ParameterBlockSize(block);
    const int tangent = problem.ParameterBlockTangentSize(block);
    RowMajorMatrix jacobian = RowMajorMatrix::Identity(ambient, tangent);
    if (const ceres::Manifold* manifold = problem.GetManifold(block))
      manifold->PlusJacobian(block, jacobian.data());
    p.block(b.ambient_offset[k], b.tangent_offset[k], ambient, tangent) = jacobian;
  }
  return p;
}

// What a group of frames contributes to the least-squares problem in the camera blocks'
// tangent coordinates, each track's point profiled out: the gradient J^T r and the
// Gauss-Newton matrix J^T J.
struct GroupTerms {
  Eigen::VectorXd gradient;
  Eigen::MatrixXd normal;
};

// A residual block's Jacobians with respect to the camera blocks it involves (tangent
// coordinates, loss applied as the solver sees it); false if it could not be evaluated.
struct BlockJacobian {
  size_t block = 0;  // position in CameraBlocks::blocks
  RowMajorMatrix jacobian;
};
bool EvaluateBlock(ceres::Problem& problem, const CameraBlocks& b, ceres::ResidualBlockId id,
                   const double* point, double* residuals, std::vector<BlockJacobian>* cameras,
                   RowMajorMatrix* point_jacobian) {
  std::vector<double*> parameters;
  problem.GetParameterBlocksForResidualBlock(id, &parameters);
  std::vector<RowMajorMatrix> jacobians(parameters.size());
  std::vector<double*> pointers(parameters.size(), nullptr);
  const int rows = problem.GetCostFunctionForResidualBlock(id)->num_residuals();
  for (size_t k = 0; k < parameters.size(); ++k) {
    if (problem.IsParameterBlockConstant(parameters[k])) continue;
    jacobians[k].resize(rows, problem.ParameterBlockTangentSize(parameters[k]));
    pointers[k] = jacobians[k].data();
  }
  double cost = 0.0;
  if (!problem.EvaluateResidualBlock(id, true, &cost, residuals, pointers.data())) return false;
  for (size_t k = 0; k < parameters.size(); ++k) {
    if (pointers[k] == nullptr) continue;
    if (parameters[k] == point) {
      *point_jacobian = std::move(jacobians[k]);
    } else if (const auto it = b.index.find(parameters[k]); it != b.index.end()) {
      cameras->push_back({it->second, std::move(jacobians[k])});
    }
  }
  return true;
}

// Adds J^T r and J^T J of rows whose camera Jacobians are `cameras` (each `rows` x tangent,
// zero outside its own rows) to `terms`.
void Accumulate(const CameraBlocks& b, const std::vector<BlockJacobian>& cameras,
                const Eigen::VectorXd& residuals, GroupTerms* terms) {
  for (const BlockJacobian& u : cameras) {
    const int ou = b.tangent_offset[u.block];
    terms->gradient.segment(ou, u.jacobian.cols()) += u.jacobian.transpose() * residuals;
    for (const BlockJacobian& v : cameras) {
      terms->normal.block(ou, b.tangent_offset[v.block], u.jacobian.cols(), v.jacobian.cols()) +=
          u.jacobian.transpose() * v.jacobian;
    }
  }
}

// Adds one track's two observations to `terms`, its point profiled out: residuals and camera
// Jacobians are projected off the directions the point can absorb. False if a block could
// not be evaluated or the point is not determined.
bool AddTrack(ceres::Problem& problem, const CameraBlocks& b, const double* point,
              const std::vector<ceres::ResidualBlockId>& ids, GroupTerms* terms) {
  const Eigen::Index rows = 2 * static_cast<Eigen::Index>(ids.size());
  Eigen::VectorXd residuals(rows);
  Eigen::MatrixXd point_jacobian(rows, 3);
  std::vector<BlockJacobian> cameras;
  for (size_t i = 0; i < ids.size(); ++i) {
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
    std::vector<BlockJacobian> own;
    RowMajorMatrix jp;
    if (!EvaluateBlock(problem, b, ids[i], point, residuals.data() + row, &own, &jp) ||
        jp.rows() != 2)
      return false;
    point_jacobian.middleRows(row, 2) = jp;
    for (BlockJacobian& u : own) {
      RowMajorMatrix full = RowMajorMatrix::Zero(rows, u.jacobian.cols());
      full.middleRows(row, 2) = u.jacobian;
      cameras.push_back({u.block, std::move(full)});
    }
  }
  const Eigen::LDLT<Eigen::Matrix3d> solver(point_jacobian.transpose() * point_jacobian);
  if (solver.info() != Eigen::Success || solver.rcond() < 1e-12) return false;
  const Eigen::MatrixXd off = Eigen::MatrixXd::Identity(rows, rows) -
                              point_jacobian * solver.solve(point_jacobian.transpose());
  for (BlockJacobian& u : cameras)
    u.jacobian = off * u.jacobian;
  Accumulate(b, cameras, off * residuals, terms);
  return true;
}

// The residual blocks of a problem by what they constrain: per point its observations, and
// the blocks on one parameter block alone (the principal point priors). Built in one pass:
// Ceres answers "which residual blocks use this parameter block" by scanning them all.
struct ResidualIndex {
  std::unordered_map<const double*, std::vector<ceres::ResidualBlockId>> by_point;
  std::vector<ceres::ResidualBlockId> priors;
};

ResidualIndex IndexResiduals(const ceres::Problem& problem, const CameraBlocks& b) {
  ResidualIndex index;
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  std::vector<double*> parameters;
  for (const ceres::ResidualBlockId id : ids) {
    problem.GetParameterBlocksForResidualBlock(id, &parameters);
    if (parameters.size() == 1) {
      index.priors.push_back(id);
      continue;
    }
    for (const double* p : parameters) {
      if (!b.index.contains(p)) index.by_point[p].push_back(id);
    }
  }
  return index;
}

// Adds the priors' J^T r and J^T J to `terms`: they belong to no group of frames.
bool AddPriors(ceres::Problem& problem, const CameraBlocks& b,
               const std::vector<ceres::ResidualBlockId>& priors, GroupTerms* terms) {
  for (const ceres::ResidualBlockId id : priors) {
    Eigen::VectorXd residuals(problem.GetCostFunctionForResidualBlock(id)->num_residuals());
    std::vector<BlockJacobian> own;
    RowMajorMatrix unused;
    if (!EvaluateBlock(problem, b, id, nullptr, residuals.data(), &own, &unused)) return false;
    Accumulate(b, own, residuals, terms);
  }
  return true;
}

// The delete-a-group jackknife covariance of the camera blocks, ambient coordinates: each
// group of `frames_per_group` consecutive frames is left out in turn, the solution moved by
// one Gauss-Newton step (H - H_g)^-1 g_g, and the spread of those moves, (G-1)/G sum of
// their centred outer products, taken as the covariance. Errors correlated within a group
// count as what they are, and a group that alone holds a direction weighs as it should
// (which the plain cluster-robust sandwich underrates). A group without which some camera
// would not be held at all is not left out. Empty if fewer than two groups can be.
Eigen::MatrixXd GroupedCovariance(const MetricScene& scene, const EuclideanProblem& built,
                                  const CameraBlocks& b, int frames_per_group) {
  ceres::Problem& problem = *built.problem;
  const GroupTerms zero{Eigen::VectorXd::Zero(b.tangent),
                        Eigen::MatrixXd::Zero(b.tangent, b.tangent)};
  const ResidualIndex residuals = IndexResiduals(problem, b);
  std::map<uint64_t, GroupTerms> groups;
  for (size_t k = 0; k < scene.tracks.size(); ++k) {
    const double* point = scene.points[k].data();
    const auto ids = residuals.by_point.find(point);
    if (!scene.inlier[k] || ids == residuals.by_point.end()) continue;
    auto [it, added] = groups.try_emplace(scene.tracks[k].frame / frames_per_group, zero);
    if (!AddTrack(problem, b, point, ids->second, &it->second)) return {};
  }
  if (groups.size() < 2) return {};
  GroupTerms all = zero;
  if (!AddPriors(problem, b, residuals.priors, &all)) return {};
  for (const auto& [group, terms] : groups)
    all.normal += terms.normal;
  // Held blocks have no tangent direction: identity there keeps the matrices invertible.
  for (size_t k = 0; k < b.blocks.size(); ++k) {
    if (!problem.IsParameterBlockConstant(b.blocks[k])) continue;
    const int size = problem.ParameterBlockTangentSize(b.blocks[k]);
    all.normal.block(b.tangent_offset[k], b.tangent_offset[k], size, size).setIdentity();
  }
  // Solved in Jacobi-scaled coordinates (unit diagonal), so that the conditioning test
  // compares directions, not units (pixels of focal length against radians).
  const Eigen::VectorXd scale = all.normal.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  std::vector<Eigen::VectorXd> moves;
  for (const auto& [group, terms] : groups) {
    const Eigen::LDLT<Eigen::MatrixXd> solver(scale.asDiagonal() * (all.normal - terms.normal) *
                                              scale.asDiagonal());
    if (solver.info() != Eigen::Success || !solver.isPositive() || solver.rcond() < 1e-10) {
      // Nothing to leave out: without this group some camera is not held at all (one seen
      // in these frames only). Its figures stay the independent ones (the larger is taken).
      spdlog::debug("camera uncertainty: frames {}-{} alone hold a camera; not left out",
                    group * frames_per_group, (group + 1) * frames_per_group - 1);
      continue;
    }
    moves.push_back(scale.asDiagonal() * solver.solve(scale.asDiagonal() * terms.gradient));
  }
  if (moves.size() < 2) return {};
  const double count = static_cast<double>(moves.size());
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(b.tangent);
  for (const Eigen::VectorXd& move : moves)
    mean += move / count;
  Eigen::MatrixXd tangent = Eigen::MatrixXd::Zero(b.tangent, b.tangent);
  for (const Eigen::VectorXd& move : moves)
    tangent.selfadjointView<Eigen::Lower>().rankUpdate(move - mean);
  tangent = tangent.selfadjointView<Eigen::Lower>();
  tangent *= (count - 1.0) / count;
  const Eigen::MatrixXd plus = PlusJacobian(problem, b);
  return plus * tangent * plus.transpose();
}

// Per-camera figures from a covariance of the camera blocks (ambient coordinates, already
// scaled): poses as (rotation error, centre) in the centre-aligned gauge unless a camera is
// held, intrinsics as they are.
std::vector<CameraUncertainty> Figures(const MetricScene& scene, const EuclideanProblem& built,
                                       const CameraBlocks& b, const Eigen::MatrixXd& ambient) {
  std::vector<CameraUncertainty> out(scene.cameras.size());
  const Eigen::Index m = static_cast<Eigen::Index>(b.cameras.size());
  Eigen::MatrixXd pose_covariance(6 * m, 6 * m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j)
      pose_covariance.block<6, 6>(6 * i, 6 * j) =
          ambient.block<6, 6>(b.ambient_offset[static_cast<size_t>(2 * i)],
                              b.ambient_offset[static_cast<size_t>(2 * j)]);
  }
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(6 * m, 6 * m);
  std::vector<Eigen::Vector3d> centres;
  double diameter = 0.0;
  bool any_held = false;
  for (Eigen::Index k = 0; k < m; ++k) {
    const size_t c = b.cameras[static_cast<size_t>(k)];
    jacobian.block<6, 6>(6 * k, 6 * k) = PoseJacobian(built.poses[c]);
    centres.push_back(scene.cameras[c].Center());
    any_held = any_held || scene.Held(c);
    for (const Eigen::Vector3d& other : centres)
      diameter = std::max(diameter, (other - centres.back()).norm());
  }
  Eigen::MatrixXd pose_sigma = jacobian * pose_covariance * jacobian.transpose();
  if (!any_held && diameter > 0.0) pose_sigma = ToCentreGauge(pose_sigma, centres, diameter);
  for (Eigen::Index k = 0; k < m; ++k) {
    const size_t c = b.cameras[static_cast<size_t>(k)];
    const int intrinsics = b.ambient_offset[static_cast<size_t>(2 * k + 1)];
    CameraUncertainty& u = out[c];
    u.estimated = true;
    u.rotation_deg = kDegrees * std::sqrt(pose_sigma.block<3, 3>(6 * k, 6 * k).trace());
    u.center_rel = diameter > 0.0
                       ? std::sqrt(pose_sigma.block<3, 3>(6 * k + 3, 6 * k + 3).trace()) / diameter
                       : 0.0;
    u.focal_rel = std::sqrt(ambient(intrinsics, intrinsics)) / scene.cameras[c].K(0, 0);
    u.principal_px = std::sqrt(ambient(intrinsics + 2, intrinsics + 2) +
                               ambient(intrinsics + 3, intrinsics + 3));
  }
  return out;
}

// The larger of two estimates, figure by figure.
void TakeLarger(const std::vector<CameraUncertainty>& other, std::vector<CameraUncertainty>* out) {
  for (size_t c = 0; c < out->size(); ++c) {
    CameraUncertainty& u = (*out)[c];
    const CameraUncertainty& v = other[c];
    if (!u.estimated || !v.estimated) continue;
    u.rotation_deg = std::max(u.rotation_deg, v.rotation_deg);
    u.center_rel = std::max(u.center_rel, v.center_rel);
    u.focal_rel = std::max(u.focal_rel, v.focal_rel);
    u.principal_px = std::max(u.principal_px, v.principal_px);
  }
}

}  // namespace

std::vector<CameraUncertainty> EstimateCameraUncertainty(const MetricScene& scene,
                                                         const IntrinsicsModel& model,
                                                         const BundleOptions& options,
                                                         const UncertaintyOptions& uncertainty) {
  const size_t n = scene.cameras.size();
  MetricScene anchored = scene;
  const std::unique_ptr<EuclideanProblem> built = BuildEuclideanProblem(&anchored, model, options);
  ceres::Problem& problem = *built->problem;
  if (problem.NumResidualBlocks() == 0) return std::vector<CameraUncertainty>(n);
  const CameraBlocks blocks = CollectCameraBlocks(anchored, *built);

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
  if (dof <= 0) return std::vector<CameraUncertainty>(n);
  const double variance = sum2 / dof;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  covariance_options.num_threads = options.threads;
  ceres::Covariance covariance(covariance_options);
  if (!covariance.Compute(blocks.blocks, &problem)) {
    spdlog::warn("camera uncertainty: the bundle adjustment's covariance is rank deficient");
    return std::vector<CameraUncertainty>(n);
  }
  RowMajorMatrix ambient(blocks.ambient, blocks.ambient);
  if (!covariance.GetCovarianceMatrix(blocks.blocks, ambient.data()))
    return std::vector<CameraUncertainty>(n);
  std::vector<CameraUncertainty> out = Figures(anchored, *built, blocks, variance * ambient);
  if (uncertainty.frames_per_group > 0) {
    const Eigen::MatrixXd grouped =
        GroupedCovariance(anchored, *built, blocks, uncertainty.frames_per_group);
    if (grouped.size() > 0) TakeLarger(Figures(anchored, *built, blocks, grouped), &out);
  }
  return out;
}

}  // namespace silnet::aggregator
