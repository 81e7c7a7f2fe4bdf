#include "aggregator/pairwise/epipolar_tangent_ransac.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "aggregator/pairwise/fundamental_distance.h"
#include "aggregator/pairwise/keyframes.h"
#include "aggregator/pairwise/pair_degeneracy.h"
#include "aggregator/pairwise/ransac_driver.h"
#include "shared/silhouette/hull_tangents.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

// The homogeneous line through `point` with direction `angle`.
Eigen::Vector3d LineWithDirection(const Eigen::Vector2d& point, double angle) {
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
  return Eigen::Vector3d(d.y(), -d.x(), d.x() * point.y() - d.y() * point.x());
}

// An epipole from two random directed tangents of a hull (thesis 2.3.3): the first direction
// uniform, the second turned by z ~ N(pi, sigma). Half the draws use a narrow sigma (distant
// epipoles, the common case around a ring), half a wide one (epipoles close to the subject).
Eigen::Vector3d EpipoleFromTangents(const SilhouetteHull& hull, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uniform(0.0, 2.0 * std::numbers::pi);
  std::normal_distribution<double> turn(std::numbers::pi, (rng() & 1) != 0 ? 0.6 : 2.0);
  const double first = uniform(rng);
  const double second = first - turn(rng);
  const Eigen::Vector3d l1 = LineWithDirection(hull.vertex(SupportingVertex(hull, first)), first);
  const Eigen::Vector3d l2 = LineWithDirection(hull.vertex(SupportingVertex(hull, second)), second);
  return l1.cross(l2).normalized();
}

// A small random rotation of a unit vector.
Eigen::Vector3d Perturb(const Eigen::Vector3d& e, double spread, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, spread);
  return (e + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).normalized();
}

// The hypothesis generator and verifier of the RANSAC driver.
class EpipolarTangentEstimator {
 public:
  using Model = EpipolarModel;
  using Score = HypothesisScore;

  EpipolarTangentEstimator(const SilhouetteSequence& i, const SilhouetteSequence& j,
                           double quantile)
      : i_(i), j_(j) {
    scoring_.quantile = quantile;
  }

  // Frames verified (in this order) and frames hypotheses are drawn from.
  void SetFrames(std::vector<uint64_t> verification, std::vector<uint64_t> sampling) {
    verification_ = std::move(verification);
    sampling_ = std::move(sampling);
  }
  void SetOffsetRange(double lo, double hi, bool integer) {
    offset_lo_ = lo;
    offset_hi_ = hi;
    integer_offsets_ = integer;
  }
  void SetSeeds(std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> seeds) {
    seeds_ = std::move(seeds);
  }
  void SetTau(double tau) { scoring_.tau = tau; }
  double tau() const { return scoring_.tau; }

  void Hypothesize(std::mt19937_64& rng, std::vector<Model>* models) {
    if (sampling_.size() < 2) return;
    std::uniform_int_distribution<size_t> pick(0, sampling_.size() - 1);
    for (int attempt = 0; attempt < 20; ++attempt) {
      const double offset = SampleOffset(rng);
      const uint64_t a = sampling_[pick(rng)], b = sampling_[pick(rng)];
      if (a == b) continue;
      const SilhouetteFrame* ia = i_.Usable(a);
      const SilhouetteFrame* ib = i_.Usable(b);
      const SilhouetteFrame *ja0, *ja1, *jb0, *jb1;
      double fa = 0, fb = 0;
      if (ia == nullptr || ib == nullptr || !BracketInJ(j_, a, offset, &ja0, &ja1, &fa) ||
          !BracketInJ(j_, b, offset, &jb0, &jb1, &fb)) {
        continue;
      }
      Eigen::Vector3d e_i, e_j;
      std::uniform_real_distribution<double> coin(0.0, 1.0);
      if (!seeds_.empty() && coin(rng) < 0.7) {
        const auto& seed = seeds_[std::uniform_int_distribution<size_t>(0, seeds_.size() - 1)(rng)];
        e_i = Perturb(seed.first, 0.01, rng);
        e_j = Perturb(seed.second, 0.01, rng);
      } else {
        e_i = EpipoleFromTangents(ia->hull, rng);
        e_j = EpipoleFromTangents(fa < 0.5 ? ja0->hull : ja1->hull, rng);
      }
      const OuterTangents ti_a = ComputeOuterTangents(ia->hull, e_i);
      const OuterTangents tj_a = Interpolate(ComputeOuterTangents(ja0->hull, e_j),
                                             ComputeOuterTangents(ja1->hull, e_j), fa);
      const OuterTangents ti_b = ComputeOuterTangents(ib->hull, e_i);
      const OuterTangents tj_b = Interpolate(ComputeOuterTangents(jb0->hull, e_j),
                                             ComputeOuterTangents(jb1->hull, e_j), fb);
      if (!ti_a.exists || !tj_a.exists || !ti_b.exists || !tj_b.exists) continue;
      if (!(ti_a.valid[0] && ti_a.valid[1] && tj_a.valid[0] && tj_a.valid[1])) continue;
      const int side = coin(rng) < 0.5 ? 0 : 1;
      if (!ti_b.valid[side]) continue;
      const PencilBasis pi = PencilBasis::For(e_i), pj = PencilBasis::For(e_j);
      auto line = [](const Eigen::Vector3d& e, const Eigen::Vector2d& x) {
        return e.cross(x.homogeneous());
      };
      for (int crossed = 0; crossed < 2; ++crossed) {
        for (int partner = 0; partner < 2; ++partner) {
          if (!tj_b.valid[partner]) continue;
          const std::array<Eigen::Vector3d, 3> li = {
              line(pi.e, ti_a.point[0]), line(pi.e, ti_a.point[1]), line(pi.e, ti_b.point[side])};
          const std::array<Eigen::Vector3d, 3> lj = {line(pj.e, tj_a.point[crossed]),
                                                     line(pj.e, tj_a.point[1 - crossed]),
                                                     line(pj.e, tj_b.point[partner])};
          const auto h = SolveLineHomography(pi, pj, li, lj);
          if (!h) continue;
          EpipolarModel model;
          model.pencil_i = pi;
          model.pencil_j = pj;
          model.h = *h;
          model.offset = offset;
          models->push_back(model);
        }
      }
      return;
    }
  }

  Score Verify(const Model& model) {
    return ScoreHypothesis(model, i_, j_, verification_, scoring_, &errors_);
  }

 private:
  double SampleOffset(std::mt19937_64& rng) const {
    if (offset_hi_ <= offset_lo_) return offset_lo_;
    if (integer_offsets_) {
      return static_cast<double>(std::uniform_int_distribution<long>(
          std::lround(std::ceil(offset_lo_)), std::lround(std::floor(offset_hi_)))(rng));
    }
    return std::uniform_real_distribution<double>(offset_lo_, offset_hi_)(rng);
  }

  const SilhouetteSequence& i_;
  const SilhouetteSequence& j_;
  std::vector<uint64_t> verification_, sampling_;
  double offset_lo_ = 0.0, offset_hi_ = 0.0;
  bool integer_offsets_ = true;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> seeds_;
  ScoringOptions scoring_;
  std::vector<double> errors_;
};

// tau0 from preliminary iterations (thesis 2.3.5): start at tau_start, lower it to every
// smaller K-quantile seen; accept it when it falls below tau_min or stalls for `patience`.
double TuneThreshold(EpipolarTangentEstimator& estimator, const PairwiseOptions& options,
                     double tau_min, size_t budget, std::mt19937_64& rng, size_t* iterations) {
  double tau = options.tau_start;
  int stalled = 0;
  std::vector<EpipolarModel> models;
  for (size_t it = 0; it < budget; ++it) {
    ++*iterations;
    models.clear();
    estimator.SetTau(tau + 1.0);
    estimator.Hypothesize(rng, &models);
    for (const EpipolarModel& model : models) {
      const HypothesisScore score = estimator.Verify(model);
      if (!score.promising) continue;
      if (score.quantile_error < tau) {
        tau = score.quantile_error;
        stalled = 0;
      } else {
        ++stalled;
      }
    }
    if (tau < tau_min || stalled >= options.tau_patience) break;
  }
  return std::max(tau, tau_min);
}

// How far the silhouettes move: the RMS, over eight tangent directions, of the standard
// deviation of the extremal hull points over the usable frames, in pixels.
double SilhouetteMotion(const SilhouetteSequence& s) {
  double total = 0.0;
  for (int d = 0; d < 8; ++d) {
    const double angle = d * std::numbers::pi / 4.0;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double square = 0.0;
    size_t n = 0;
    for (const SilhouetteFrame& f : s.frames) {
      if (s.Usable(f.index) == nullptr) continue;
      const Eigen::Vector2d p = f.hull.vertex(SupportingVertex(f.hull, angle));
      sum += p;
      square += p.squaredNorm();
      ++n;
    }
    if (n == 0) return 0.0;
    const Eigen::Vector2d mean = sum / static_cast<double>(n);
    total += std::max(0.0, square / static_cast<double>(n) - mean.squaredNorm());
  }
  return std::sqrt(total / 8.0);
}

std::vector<uint64_t> Shuffled(std::vector<uint64_t> frames, std::mt19937_64& rng) {
  std::shuffle(frames.begin(), frames.end(), rng);
  return frames;
}

}  // namespace

std::string PairwiseOptions::Validate() const {
  if (!(quantile > 0.0 && quantile < 1.0)) return "quantile must lie in (0, 1)";
  if (!(tau_start > 0.0) || !(final_threshold > 0.0)) return "thresholds must be positive";
  if (max_iterations < 100) return "at least 100 iterations";
  if (!synchronized && !(offset_max >= offset_min)) return "offset range is empty";
  if (agreeing < 1) return "agreeing must be at least 1";
  if (!(local_support > 0.0 && local_support <= 1.0)) return "local_support must lie in (0, 1]";
  if (!(local_fit_px > 0.0)) return "local_fit_px must be positive";
  if (give_up_iterations != 0 && give_up_iterations < 1000)
    return "give_up_iterations must be 0 (never) or at least 1000";
  return {};
}

PairCandidate PairwiseResult::Chosen() const {
  return {model,         F, offset, offset_sigma, inliers, residual_rms, candidates_agreeing,
          inlier_matches};
}

void PairwiseResult::Adopt(PairCandidate candidate) {
  model = candidate.model;
  F = candidate.F;
  offset = candidate.offset;
  offset_sigma = candidate.offset_sigma;
  inliers = candidate.inliers;
  residual_rms = candidate.residual_rms;
  candidates_agreeing = candidate.support;
  inlier_matches = std::move(candidate.inlier_matches);
}

void PairwiseResult::Choose(size_t alternative, const std::string& why) {
  SILNET_CHECK(alternative < alternatives.size());
  PairCandidate chosen = std::move(alternatives[alternative]);
  alternatives[alternative] = Chosen();
  Adopt(std::move(chosen));
  status = PairStatus::kOk;
  reason = why;
}

const char* ToString(PairStatus status) {
  switch (status) {
    case PairStatus::kOk:
      return "ok";
    case PairStatus::kDegenerate:
      return "degenerate";
    case PairStatus::kFailed:
      return "failed";
    case PairStatus::kAmbiguous:
      return "ambiguous";
  }
  return "unknown";
}

PairwiseOptions ScaledToImages(const PairwiseOptions& options, int width_i, int height_i,
                               int width_j, int height_j) {
  const double scale = std::max(1.0, static_cast<double>(width_i + height_i + width_j + height_j) /
                                         (2.0 * (kReferenceWidth + kReferenceHeight)));
  PairwiseOptions scaled = options;
  scaled.tau_start *= scale;
  scaled.screen_min *= scale;
  scaled.screen_max *= scale;
  scaled.ambiguity_px *= scale;
  scaled.min_motion_px *= scale;
  return scaled;
}

PairwiseResult EstimatePair(const SilhouetteSequence& i, const SilhouetteSequence& j,
                            const PairwiseOptions& given, Progress* progress) {
  const PairwiseOptions options = ScaledToImages(given, i.width, i.height, j.width, j.height);
  const auto start = Clock::now();
  PairwiseResult result;
  result.camera_i = i.camera_id;
  result.camera_j = j.camera_id;
  auto finish = [&](PairStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
  };
  if (const std::string reason = options.Validate(); !reason.empty())
    return finish(PairStatus::kFailed, reason);
  std::mt19937_64 rng(options.seed);
  const std::vector<uint64_t> all_frames = UsableFrames(i);
  if (all_frames.size() < 30 || UsableFrames(j).size() < 30) {
    return finish(PairStatus::kFailed, "fewer than 30 usable silhouettes in a view");
  }
  for (const SilhouetteSequence* s : {&i, &j}) {
    const double motion = SilhouetteMotion(*s);
    if (motion < options.min_motion_px) {
      return finish(
          PairStatus::kDegenerate,
          fmt::format("too little motion: the silhouettes of {} move {:.1f} px (less than {:.0f})",
                      s->camera_id, motion, options.min_motion_px));
    }
  }
  const double tau_min = 0.005 * (i.width + i.height);
  EpipolarTangentEstimator estimator(i, j, options.quantile);
  size_t budget = options.max_iterations;
  auto spend = [&](size_t used) { budget = used >= budget ? 0 : budget - used; };

  // The offset range: fixed for synchronised cameras, else the options' range, narrowed by a
  // prior (node timestamps) when there is one.
  double lo = 0.0, hi = 0.0;
  if (!options.synchronized) {
    lo = options.offset_min;
    hi = options.offset_max;
    if (options.offset_prior) {
      lo = std::max(lo, *options.offset_prior - 3.0 * options.prior_sigma);
      hi = std::min(hi, *options.offset_prior + 3.0 * options.prior_sigma);
    }
  }
  const bool coarse_phase = !options.synchronized && hi - lo > 10.0;
  const std::vector<uint64_t> shuffled = Shuffled(all_frames, rng);
  const std::vector<uint64_t> local_frames(
      shuffled.begin(), shuffled.begin() + static_cast<std::ptrdiff_t>(
                                               std::min(options.local_frames, shuffled.size())));
  // Coarse phase (thesis 2.5.1): over a wide offset range, hypotheses are verified on the slow
  // keyframes, which tolerate an offset a few frames off; local optimisation then fixes the
  // offset. Fine phase: around the offset found (or the fixed one), all frames.
  if (coarse_phase) {
    const Keyframes keyframes = SelectKeyframes(i);
    estimator.SetFrames(Shuffled(keyframes.slow, rng), all_frames);
    estimator.SetOffsetRange(lo, hi, true);
  } else {
    estimator.SetFrames(shuffled, all_frames);
    estimator.SetOffsetRange(lo, hi, options.synchronized);
  }
  size_t used = 0;
  const double tau0 =
      TuneThreshold(estimator, options, tau_min,
                    std::min<size_t>(budget / 8, options.tuning_iterations), rng, &used);
  result.iterations += used;
  spend(used);
  result.tau0 = tau0;
  const double screen =
      std::clamp(options.screen_factor * tau0, options.screen_min, options.screen_max);
  estimator.SetTau(screen);
  RefinementOptions local;
  local.initial_threshold = screen;
  local.final_threshold = options.local_fit_px;
  local.max_rounds = 5;
  local.max_matches = 150;
  local.refine_offset = !options.synchronized;
  local.max_offset_step = 3.0;
  local.abort_fraction = 0.5 * options.local_support;
  RefinementOptions full;
  full.initial_threshold = 4.0;
  full.final_threshold = options.final_threshold;
  full.refine_offset = !options.synchronized;
  full.estimate_offset_sigma = true;
  struct Solution {
    RefinedModel refined;
    Eigen::Matrix3d f;
    size_t support = 1;
  };
  std::vector<Solution> solutions;
  bool fine_phase = !coarse_phase;
  const double possible_local = 2.0 * static_cast<double>(local_frames.size());
  auto on_candidate = [&](const RansacCandidate<EpipolarModel, HypothesisScore>& candidate) {
    ++result.candidates_refined;
    const RefinedModel lo_model =
        RefineEpipolarModel(candidate.model, i, j, local_frames, local, &rng);
    result.best_local_support =
        std::max(result.best_local_support, static_cast<double>(lo_model.inliers) / possible_local);
    if (!lo_model.valid ||
        static_cast<double>(lo_model.inliers) < options.local_support * possible_local) {
      return result.candidates_refined >= options.max_local_optimisations;
    }
    const Eigen::Matrix3d f = lo_model.model.Fundamental();
    for (Solution& s : solutions) {
      if (FundamentalDistance(f, s.f, i.width, i.height) < options.consensus_px &&
          std::abs(lo_model.model.offset - s.refined.model.offset) < 0.5) {
        ++s.support;
        return s.support >= options.agreeing;
      }
    }
    RefinedModel refined = RefineEpipolarModel(lo_model.model, i, j, all_frames, full, &rng);
    if (!refined.valid) return false;
    const Eigen::Matrix3d refined_f = refined.model.Fundamental();
    // A full refinement may land on a solution already held (the local one was rougher).
    for (Solution& s : solutions) {
      if (FundamentalDistance(refined_f, s.f, i.width, i.height) < options.consensus_px &&
          std::abs(refined.model.offset - s.refined.model.offset) < 0.5) {
        ++s.support;
        if (refined.inliers > s.refined.inliers) {
          s.refined = std::move(refined);
          s.f = refined_f;
        }
        return s.support >= options.agreeing;
      }
    }
    solutions.push_back(Solution{std::move(refined), refined_f, 1});
    if (!fine_phase) {
      // The first solution fixes the offset to about a frame: switch to the fine phase around
      // it, seeding epipoles near the solution's.
      fine_phase = true;
      const double found = solutions.back().refined.model.offset;
      spdlog::debug("{}-{}: coarse phase found offset {:.2f} after {} candidates", i.camera_id,
                    j.camera_id, found, result.candidates_refined);
      estimator.SetFrames(shuffled, all_frames);
      estimator.SetOffsetRange(std::max(lo, found - 2.0), std::min(hi, found + 2.0), false);
    }
    estimator.SetSeeds(
        {{solutions.back().refined.model.pencil_i.e, solutions.back().refined.model.pencil_j.e}});
    return options.agreeing <= 1 || result.candidates_refined >= options.max_local_optimisations;
  };
  RansacLimits limits;
  limits.max_iterations = std::max<size_t>(1, budget);
  limits.max_dry_rounds = options.give_up_iterations;
  limits.candidates = std::max<size_t>(
      options.max_local_optimisations,
      std::max<size_t>(options.min_candidates, static_cast<size_t>(std::ceil(2.0 * tau0))));
  const auto report = RunRansac(estimator, limits, rng, progress, on_candidate);
  result.iterations += report.iterations;
  result.candidates = report.candidates.size();
  if (report.cancelled) return finish(PairStatus::kFailed, "cancelled");
  if (report.dry && solutions.empty()) {
    return finish(
        PairStatus::kFailed,
        fmt::format("gave up: no hypothesis passed the screen ({:.0f} px) in {} "
                    "iterations in a row ({} iterations, {} screened)",
                    screen, options.give_up_iterations, result.iterations, result.candidates));
  }
  if (solutions.empty()) {
    return finish(
        PairStatus::kFailed,
        fmt::format("no hypothesis converged in {} iterations ({} screened; the best "
                    "local fit {:.0f} % of the frontier correspondences within {:.1f} px, {:.0f} % "
                    "needed)",
                    result.iterations, result.candidates, 100.0 * result.best_local_support,
                    options.local_fit_px, 100.0 * options.local_support));
  }
  std::sort(solutions.begin(), solutions.end(), [](const Solution& a, const Solution& b) {
    return a.support != b.support ? a.support > b.support : a.refined.inliers > b.refined.inliers;
  });
  const Solution& chosen = solutions.front();
  // The offset refinement can settle half a frame off (the frame pairing changes at every
  // whole offset): restart it half a frame to either side and keep what explains clearly more.
  RefinedModel polished = chosen.refined;
  if (!options.synchronized) {
    for (const double shift : {-0.5, 0.5}) {
      EpipolarModel restart_from = chosen.refined.model;
      restart_from.offset = std::clamp(restart_from.offset + shift, lo, hi);
      RefinedModel restarted = RefineEpipolarModel(restart_from, i, j, all_frames, full, &rng);
      if (restarted.valid &&
          static_cast<double>(restarted.inliers) > 1.1 * static_cast<double>(polished.inliers)) {
        polished = std::move(restarted);
      }
    }
  }
  const RefinedModel* best = &polished;
  result.candidates_agreeing = chosen.support;
  result.model = best->model;
  result.F = best->model.Fundamental();
  result.offset = options.synchronized ? 0.0 : best->model.offset;
  result.offset_sigma = best->offset_sigma;
  result.inliers = best->inliers;
  result.residual_rms = best->rms_error;
  result.inlier_matches = best->inlier_matches;

  // Degeneracies, with a reason.
  const SupportDiagnosis diagnosis = DiagnoseSupport(best->model, best->inlier_matches, i, j);
  result.epipole_inside_fraction = diagnosis.epipole_inside_fraction;
  result.spread_score = diagnosis.spread_score;
  if (!diagnosis.reason.empty()) return finish(PairStatus::kDegenerate, diagnosis.reason);
  // Ambiguity: other solutions, clearly different, that explain almost as much. They are
  // kept, so the network can pick the one consistent with the other pairs.
  size_t rivals = 0;
  for (size_t s = 1; s < solutions.size(); ++s) {
    const bool different =
        FundamentalDistance(solutions[s].f, chosen.f, i.width, i.height) > options.ambiguity_px ||
        std::abs(solutions[s].refined.model.offset - best->model.offset) > 1.0;
    if (!different || static_cast<double>(solutions[s].refined.inliers) <
                          options.alternative_support * static_cast<double>(best->inliers)) {
      continue;
    }
    const RefinedModel& r = solutions[s].refined;
    result.alternatives.push_back({r.model, solutions[s].f,
                                   options.synchronized ? 0.0 : r.model.offset, r.offset_sigma,
                                   r.inliers, r.rms_error, solutions[s].support, r.inlier_matches});
    if (solutions[s].support >= 2 && r.inliers >= 0.9 * static_cast<double>(best->inliers))
      ++rivals;
  }
  if (chosen.support < options.agreeing) {
    return finish(PairStatus::kAmbiguous, "unconfirmed: only " + std::to_string(chosen.support) +
                                              " of " + std::to_string(options.agreeing) +
                                              " candidates reached the solution");
  }
  if (rivals > 0) {
    return finish(PairStatus::kAmbiguous, "ambiguous: " + std::to_string(rivals + 1) +
                                              " distinct solutions with similar support");
  }
  result.alternatives.clear();
  return finish(PairStatus::kOk, "");
}

}  // namespace silnet::aggregator
