#include "aggregator/calibration/global_start.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>

#include "aggregator/calibration/relative_pose.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// One candidate's relative pose, x_j = R x_i + t.
struct CandidatePose {
  int candidate = 0;
  RelativePose pose;
};

// A usable pair between camera indices i < j with the poses of its candidates.
struct PosedPair {
  size_t pair = 0;
  size_t i = 0, j = 0;
  std::vector<CandidatePose> poses;
};

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() / kDegree;
}

// The relative pose of a candidate solution, from its essential matrix and matches.
std::optional<RelativePose> PoseOf(const std::vector<CameraModel>& cameras, size_t i, size_t j,
                                   const PairCandidate& candidate) {
  ViewGraph graph(cameras.size());
  ViewLink link;
  link.i = i;
  link.j = j;
  link.F = candidate.F;
  for (const TimedMatch& m : candidate.inlier_matches)
    link.matches.push_back({m.x_i, m.XjAt(candidate.offset), m.frame_i});
  graph.Add(std::move(link));
  return PoseOfLink(graph, cameras, i, j);
}

std::vector<PosedPair> PosePairs(const std::vector<CameraModel>& cameras,
                                 const std::vector<PairwiseResult>& pairs) {
  std::vector<PosedPair> out;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const PairwiseResult& r = pairs[p];
    if (r.status != PairStatus::kOk && r.status != PairStatus::kAmbiguous) continue;
    const size_t i = CameraIndex(cameras, r.camera_i), j = CameraIndex(cameras, r.camera_j);
    if (i >= cameras.size() || j >= cameras.size() || i == j) continue;
    PosedPair posed{p, i, j, {}};
    std::vector<PairCandidate> candidates = {r.Chosen()};
    candidates.insert(candidates.end(), r.alternatives.begin(), r.alternatives.end());
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (const auto pose = PoseOf(cameras, i, j, candidates[c]))
        posed.poses.push_back({static_cast<int>(c), *pose});
    }
    if (!posed.poses.empty()) out.push_back(std::move(posed));
  }
  return out;
}

// Absolute rotations along a random spanning forest with random candidates; cameras not
// reached stay unset. Returns the root's component.
std::vector<std::optional<Eigen::Matrix3d>> RandomTreeRotations(const std::vector<PosedPair>& pairs,
                                                                size_t n, std::mt19937_64& rng) {
  std::vector<size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::optional<Eigen::Matrix3d>> rotations(n);
  rotations[pairs[order.front()].i] = Eigen::Matrix3d::Identity();
  // Grow from the first pair's camera: add any pair with exactly one end placed.
  for (bool grown = true; grown;) {
    grown = false;
    for (size_t o : order) {
      const PosedPair& p = pairs[o];
      if (rotations[p.i].has_value() == rotations[p.j].has_value()) continue;
      const RelativePose& rel =
          p.poses[std::uniform_int_distribution<size_t>(0, p.poses.size() - 1)(rng)].pose;
      if (rotations[p.i])
        rotations[p.j] = rel.R * *rotations[p.i];
      else
        rotations[p.i] = rel.R.transpose() * *rotations[p.j];
      grown = true;
    }
  }
  return rotations;
}

// The candidate of `p` closest to the rotations, and its error in degrees.
std::pair<int, double> BestCandidate(const PosedPair& p,
                                     const std::vector<std::optional<Eigen::Matrix3d>>& rotations) {
  if (!rotations[p.i] || !rotations[p.j]) return {-1, 180.0};
  const Eigen::Matrix3d implied = *rotations[p.j] * rotations[p.i]->transpose();
  std::pair<int, double> best{-1, 180.0};
  for (size_t c = 0; c < p.poses.size(); ++c) {
    const double e = AngleDeg(p.poses[c].pose.R, implied);
    if (e < best.second) best = {static_cast<int>(c), e};
  }
  return best;
}

// Centres from baseline directions: (c_j - c_i) x d = 0 per pair, the first present camera
// at the origin and the mean baseline projection 1. Empty if the system is singular.
std::vector<Eigen::Vector3d> SolveCentres(const std::vector<bool>& present,
                                          const std::vector<std::pair<size_t, size_t>>& links,
                                          const std::vector<Eigen::Vector3d>& directions) {
  const size_t n = present.size();
  std::vector<int> column(n, -1);
  size_t root = n, unknowns = 0;
  for (size_t c = 0; c < n; ++c) {
    if (!present[c]) continue;
    if (root == n) {
      root = c;
      continue;
    }
    column[c] = static_cast<int>(3 * unknowns++);
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * links.size() + 1, 3 * unknowns);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(A.rows());
  for (size_t l = 0; l < links.size(); ++l) {
    const auto [i, j] = links[l];
    const Eigen::Vector3d& d = directions[l];
    const Eigen::Matrix3d cross = Skew(d);
    if (column[j] >= 0) A.block<3, 3>(3 * l, column[j]) += cross;
    if (column[i] >= 0) A.block<3, 3>(3 * l, column[i]) -= cross;
    if (column[j] >= 0) A.block<1, 3>(3 * links.size(), column[j]) += d.transpose();
    if (column[i] >= 0) A.block<1, 3>(3 * links.size(), column[i]) -= d.transpose();
  }
  A.row(3 * links.size()) *= 10.0;
  b(3 * links.size()) = 10.0 * static_cast<double>(links.size());
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < static_cast<Eigen::Index>(3 * unknowns)) return {};
  const Eigen::VectorXd x = qr.solve(b);
  std::vector<Eigen::Vector3d> centres(n, Eigen::Vector3d::Zero());
  for (size_t c = 0; c < n; ++c) {
    if (column[c] >= 0) centres[c] = x.segment<3>(column[c]);
  }
  return centres;
}

}  // namespace

GlobalStart EstimateGlobalStart(const std::vector<CameraModel>& cameras,
                                const std::vector<PairwiseResult>& pairs,
                                const GlobalStartOptions& options) {
  const size_t n = cameras.size();
  GlobalStart out;
  out.candidate.assign(pairs.size(), -1);
  out.rotation_error_deg.assign(pairs.size(), -1.0);
  const std::vector<PosedPair> posed = PosePairs(cameras, pairs);
  if (posed.size() < 2) {
    out.reason = "fewer than two pairs give a relative pose";
    return out;
  }
  // RANSAC over spanning trees: the rotations most pairs agree with.
  std::mt19937_64 rng(options.seed);
  std::vector<std::optional<Eigen::Matrix3d>> best;
  size_t best_agreeing = 0;
  double best_error = 0.0;
  for (size_t trial = 0; trial < options.trials; ++trial) {
    const auto rotations = RandomTreeRotations(posed, n, rng);
    size_t agreeing = 0;
    double error = 0.0;
    for (const PosedPair& p : posed) {
      const auto [c, e] = BestCandidate(p, rotations);
      if (c >= 0 && e < options.rotation_tolerance_deg) ++agreeing;
      error += std::min(e, options.rotation_tolerance_deg);
    }
    if (agreeing > best_agreeing || (agreeing == best_agreeing && error < best_error)) {
      best = rotations;
      best_agreeing = agreeing;
      best_error = error;
    }
  }
  // The agreeing pairs and their candidates; then rotations averaged over them.
  std::vector<int> chosen(posed.size(), -1);
  auto select = [&] {
    for (size_t k = 0; k < posed.size(); ++k) {
      const auto [c, e] = BestCandidate(posed[k], best);
      chosen[k] = e < options.rotation_tolerance_deg ? c : -1;
    }
  };
  select();
  for (int sweep = 0; sweep < 20; ++sweep) {
    for (size_t cam = 0; cam < n; ++cam) {
      std::vector<Eigen::Matrix3d> implied;
      for (size_t k = 0; k < posed.size(); ++k) {
        if (chosen[k] < 0) continue;
        const PosedPair& p = posed[k];
        const Eigen::Matrix3d& rel = p.poses[static_cast<size_t>(chosen[k])].pose.R;
        if (p.j == cam && best[p.i]) implied.push_back(rel * *best[p.i]);
        if (p.i == cam && best[p.j]) implied.push_back(rel.transpose() * *best[p.j]);
      }
      if (!implied.empty()) best[cam] = ChordalMean(implied);
    }
  }
  select();
  // Cameras with two agreeing pairs among each other; then their centres.
  std::vector<bool> present(n);
  for (size_t c = 0; c < n; ++c)
    present[c] = best[c].has_value();
  std::vector<std::pair<size_t, size_t>> links;
  std::vector<Eigen::Vector3d> directions;
  std::vector<size_t> link_pair;
  for (int round = 0; round < 3; ++round) {
    for (bool removed = true; removed;) {
      removed = false;
      for (size_t c = 0; c < n; ++c) {
        if (!present[c]) continue;
        size_t degree = 0;
        for (size_t k = 0; k < posed.size(); ++k) {
          const PosedPair& p = posed[k];
          degree += chosen[k] >= 0 && (p.i == c || p.j == c) && present[p.i] && present[p.j];
        }
        if (degree < 2) present[c] = false, removed = true;
      }
    }
    links.clear();
    directions.clear();
    link_pair.clear();
    for (size_t k = 0; k < posed.size(); ++k) {
      const PosedPair& p = posed[k];
      if (chosen[k] < 0 || !present[p.i] || !present[p.j]) continue;
      const RelativePose& rel = posed[k].poses[static_cast<size_t>(chosen[k])].pose;
      links.emplace_back(p.i, p.j);
      directions.push_back((best[p.i]->transpose() * (-rel.R.transpose() * rel.t)).normalized());
      link_pair.push_back(k);
    }
    if (std::count(present.begin(), present.end(), true) < 3) {
      out.reason = "fewer than three cameras with two pairs that agree on their rotations";
      return out;
    }
    const std::vector<Eigen::Vector3d> centres = SolveCentres(present, links, directions);
    if (centres.empty()) {
      out.reason = "the baseline directions do not fix the camera centres";
      return out;
    }
    // Pairs whose baseline disagrees with the centres are dropped and the centres solved again.
    bool dropped = false;
    for (size_t l = 0; l < links.size(); ++l) {
      const Eigen::Vector3d baseline = centres[links[l].second] - centres[links[l].first];
      const double cos = baseline.normalized().dot(directions[l]);
      if (std::acos(std::clamp(cos, -1.0, 1.0)) / kDegree > options.direction_tolerance_deg) {
        chosen[link_pair[l]] = -1;
        dropped = true;
      }
    }
    if (!dropped) {
      out.ok = true;
      out.present = present;
      out.C = centres;
      out.R.assign(n, Eigen::Matrix3d::Identity());
      for (size_t c = 0; c < n; ++c) {
        if (present[c]) out.R[c] = *best[c];
      }
      for (size_t k = 0; k < posed.size(); ++k) {
        if (chosen[k] < 0 || !present[posed[k].i] || !present[posed[k].j]) continue;
        const CandidatePose& cp = posed[k].poses[static_cast<size_t>(chosen[k])];
        out.candidate[posed[k].pair] = cp.candidate;
        out.rotation_error_deg[posed[k].pair] =
            AngleDeg(cp.pose.R, out.R[posed[k].j] * out.R[posed[k].i].transpose());
      }
      return out;
    }
  }
  out.reason = "the baseline directions of the pairs disagree";
  return out;
}

}  // namespace silnet::aggregator
