#include "aggregator/pairwise/epipolar_refinement.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "aggregator/pairwise/hypothesis_scoring.h"
#include "aggregator/pairwise/symmetric_transfer_cost.h"

namespace silnet::aggregator {
namespace {

Eigen::Vector3d ReferenceAxis(const Eigen::Vector3d& e) {
  Eigen::Index axis = 0;
  e.cwiseAbs().minCoeff(&axis);
  return Eigen::Vector3d::Unit(axis);
}

// h expressed in the bases PencilBasis::For picks, from h in the bases built on `axis_*`.
EpipolarModel Canonical(const Eigen::Vector3d& e_i, const Eigen::Vector3d& e_j,
                        const Eigen::Vector4d& h, const Eigen::Vector3d& axis_i,
                        const Eigen::Vector3d& axis_j, double offset) {
  auto basis = [](const Eigen::Vector3d& e, const Eigen::Vector3d& axis) {
    PencilBasis b;
    b.e = e.normalized();
    b.u = axis.cross(b.e).normalized();
    b.v = b.e.cross(b.u);
    return b;
  };
  EpipolarModel solved;
  solved.pencil_i = basis(e_i, axis_i);
  solved.pencil_j = basis(e_j, axis_j);
  solved.h << h[0], h[1], h[2], h[3];
  return EpipolarModel::FromFundamental(solved.Fundamental(), offset);
}

// The offset minimising the squared transfer errors of `matches` (other parameters fixed),
// by Gauss-Newton with numeric derivatives from `start`.
double FitOffset(const EpipolarModel& model, const Eigen::Matrix3d& f,
                 const std::vector<const TimedMatch*>& matches, double start) {
  double offset = start;
  auto cost = [&](double o) {
    double sum = 0.0;
    for (const TimedMatch* m : matches) {
      const double e = TransferError(f, m->x_i, m->XjAt(o));
      sum += e * e;
    }
    return sum;
  };
  (void)model;
  for (int iteration = 0; iteration < 8; ++iteration) {
    const double h = 1e-3;
    const double c0 = cost(offset), cp = cost(offset + h), cm = cost(offset - h);
    const double gradient = (cp - cm) / (2.0 * h), curvature = (cp - 2.0 * c0 + cm) / (h * h);
    if (curvature <= 0.0) break;
    const double step = std::clamp(-gradient / curvature, -0.5, 0.5);
    offset += step;
    if (std::abs(step) < 1e-5) break;
  }
  return offset;
}

}  // namespace

double OffsetJackknifeSigma(const EpipolarModel& model, const std::vector<TimedMatch>& matches,
                            int blocks) {
  if (matches.size() < static_cast<size_t>(4 * blocks)) return 0.0;
  uint64_t first = matches.front().frame_i, last = first;
  for (const TimedMatch& m : matches) {
    first = std::min(first, m.frame_i);
    last = std::max(last, m.frame_i);
  }
  const double span = static_cast<double>(last - first + 1);
  const Eigen::Matrix3d f = model.Fundamental();
  std::vector<double> estimates;
  for (int b = 0; b < blocks; ++b) {
    std::vector<const TimedMatch*> kept;
    for (const TimedMatch& m : matches) {
      const int block = std::min(
          blocks - 1, static_cast<int>(static_cast<double>(m.frame_i - first) / span * blocks));
      if (block != b) kept.push_back(&m);
    }
    estimates.push_back(FitOffset(model, f, kept, model.offset));
  }
  double mean = 0.0;
  for (double e : estimates)
    mean += e;
  mean /= static_cast<double>(estimates.size());
  double sum = 0.0;
  for (double e : estimates)
    sum += (e - mean) * (e - mean);
  return std::sqrt((static_cast<double>(blocks) - 1.0) / static_cast<double>(blocks) * sum);
}

RefinedModel RefineEpipolarModel(const EpipolarModel& start, const SilhouetteSequence& i,
                                 const SilhouetteSequence& j, const std::vector<uint64_t>& frames_i,
                                 const RefinementOptions& options, std::mt19937_64* rng) {
  RefinedModel out;
  EpipolarModel model = start;
  double threshold = options.initial_threshold;
  size_t previous_inliers = 0;
  for (int round = 0; round < options.max_rounds; ++round) {
    out.rounds = round + 1;
    // Guided matching: frontier points from the current epipoles.
    const std::vector<TimedMatch> matches = MatchAllFrames(model, i, j, frames_i);
    const std::vector<double> errors = MatchErrors(model.Fundamental(), matches, model.offset);
    std::vector<TimedMatch> inliers;
    std::vector<double> inlier_errors;
    for (size_t m : DistinctMatches(matches, model.offset)) {
      if (errors[m] < threshold) {
        inliers.push_back(matches[m]);
        inlier_errors.push_back(errors[m]);
      }
    }
    if (inliers.size() < 12) return out;
    if (round >= 1 && options.abort_fraction > 0.0 &&
        static_cast<double>(inliers.size()) <
            options.abort_fraction * 2.0 * static_cast<double>(frames_i.size())) {
      return out;
    }
    const bool stable =
        previous_inliers > 0 &&
        std::abs(static_cast<double>(inliers.size()) - static_cast<double>(previous_inliers)) <
            0.01 * static_cast<double>(previous_inliers) + 1.0;
    previous_inliers = inliers.size();
    if (stable && round >= 2) break;
    if (inliers.size() > options.max_matches) {
      std::shuffle(inliers.begin(), inliers.end(), *rng);
      inliers.resize(options.max_matches);
    }
    // Levenberg-Marquardt on the inliers.
    Eigen::Vector3d e_i = model.pencil_i.e, e_j = model.pencil_j.e;
    Eigen::Vector4d h(model.h(0, 0), model.h(0, 1), model.h(1, 0), model.h(1, 1));
    h.normalize();
    double offset = model.offset;
    const Eigen::Vector3d axis_i = ReferenceAxis(e_i), axis_j = ReferenceAxis(e_j);
    // h in the bases built on the reference axes.
    EpipolarModel rebased = model;
    rebased.pencil_i.u = axis_i.cross(e_i).normalized();
    rebased.pencil_i.v = e_i.cross(rebased.pencil_i.u);
    rebased.pencil_j.u = axis_j.cross(e_j).normalized();
    rebased.pencil_j.v = e_j.cross(rebased.pencil_j.u);
    {
      Eigen::Matrix2d to_i, to_j;  // new-basis coordinates of old-basis coordinates
      to_i << rebased.pencil_i.u.dot(model.pencil_i.u), rebased.pencil_i.u.dot(model.pencil_i.v),
          rebased.pencil_i.v.dot(model.pencil_i.u), rebased.pencil_i.v.dot(model.pencil_i.v);
      to_j << rebased.pencil_j.u.dot(model.pencil_j.u), rebased.pencil_j.u.dot(model.pencil_j.v),
          rebased.pencil_j.v.dot(model.pencil_j.u), rebased.pencil_j.v.dot(model.pencil_j.v);
      const Eigen::Matrix2d h_new = to_j * model.h * to_i.transpose();
      h << h_new(0, 0), h_new(0, 1), h_new(1, 0), h_new(1, 1);
      h.normalize();
    }
    ceres::Problem problem;
    for (const TimedMatch& m : inliers) {
      auto* cost = new SymmetricTransferCost(
          {m.x_i, m.x_j_a, m.x_j_b,
           static_cast<double>(m.frame_i) - static_cast<double>(m.frame_j)},
          axis_i, axis_j);
      problem.AddResidualBlock(cost, new ceres::HuberLoss(1.0), e_i.data(), e_j.data(), h.data(),
                               &offset);
    }
    problem.SetManifold(e_i.data(), new ceres::SphereManifold<3>());
    problem.SetManifold(e_j.data(), new ceres::SphereManifold<3>());
    problem.SetManifold(h.data(), new ceres::SphereManifold<4>());
    if (options.refine_offset) {
      problem.SetParameterLowerBound(&offset, 0, model.offset - options.max_offset_step);
      problem.SetParameterUpperBound(&offset, 0, model.offset + options.max_offset_step);
    } else {
      problem.SetParameterBlockConstant(&offset);
    }
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.max_num_iterations = 25;
    solver.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (summary.termination_type == ceres::FAILURE) return out;
    model = Canonical(e_i, e_j, h, axis_i, axis_j, offset);
    // The threshold follows the spread of the inliers (robust sigma), within bounds.
    std::nth_element(inlier_errors.begin(),
                     inlier_errors.begin() + static_cast<std::ptrdiff_t>(inlier_errors.size() / 2),
                     inlier_errors.end());
    threshold = std::clamp(4.0 * 1.4826 * inlier_errors[inlier_errors.size() / 2],
                           options.min_threshold * 2.0, threshold);
  }
  // Final support at the strict threshold.
  const std::vector<TimedMatch> matches = MatchAllFrames(model, i, j, frames_i);
  const std::vector<double> errors = MatchErrors(model.Fundamental(), matches, model.offset);
  double sum = 0.0;
  for (size_t m : DistinctMatches(matches, model.offset)) {
    if (errors[m] < options.final_threshold) {
      out.inlier_matches.push_back(matches[m]);
      sum += errors[m] * errors[m];
    }
  }
  out.inliers = out.inlier_matches.size();
  out.rms_error = out.inliers > 0 ? std::sqrt(sum / static_cast<double>(out.inliers)) : 0.0;
  out.model = model;
  out.valid = out.inliers >= 12;
  if (options.refine_offset && options.estimate_offset_sigma && out.valid) {
    out.offset_sigma =
        std::hypot(OffsetJackknifeSigma(model, out.inlier_matches), options.offset_sigma_floor);
  }
  return out;
}

}  // namespace silnet::aggregator
