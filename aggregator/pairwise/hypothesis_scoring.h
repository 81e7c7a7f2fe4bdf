#pragma once
// Verification of an epipolar hypothesis (thesis 2.3.4): the epipolar transfer errors of
// the outer tangents of the frames, their K-quantile compared with the outlier threshold
// tau0, and early rejection once a hypothesis can no longer pass.

#include <cstddef>
#include <limits>
#include <vector>

#include "aggregator/pairwise/frame_pairing.h"

namespace silnet::aggregator {

// Settings of the K-quantile test.
struct ScoringOptions {
  double tau = 50.0;                // outlier threshold tau0, pixels
  double quantile = 0.75;           // K
  double min_match_fraction = 0.3;  // matches per evaluated frame (of 2) required
  bool early_rejection = true;      // sequential test to abandon hopeless hypotheses
};

// The outcome of verifying one hypothesis.
struct HypothesisScore {
  bool promising = false;
  double quantile_error = std::numeric_limits<double>::infinity();  // e_K
  size_t matches = 0;
  size_t frames_evaluated = 0;
};

// Verifies `model` over frames `frames_i` of camera i (in the given order: shuffle them so
// early rejection sees a fair sample). `errors` is scratch space.
HypothesisScore ScoreHypothesis(const EpipolarModel& model, const SilhouetteSequence& i,
                                const SilhouetteSequence& j, const std::vector<uint64_t>& frames_i,
                                const ScoringOptions& options, std::vector<double>* errors);

// Transfer errors of matches at time offset `offset` under `f`.
std::vector<double> MatchErrors(const Eigen::Matrix3d& f, const std::vector<TimedMatch>& matches,
                                double offset);

// Indices of matches that are not duplicates: one per 4-pixel bin of (x_i, x_j) (thesis
// 2.3.4: stationary frontier points would otherwise dominate the statistics).
std::vector<size_t> DistinctMatches(const std::vector<TimedMatch>& matches, double offset,
                                    double bin_px = 4.0);

}  // namespace silnet::aggregator
