#include "aggregator/pairwise/hypothesis_scoring.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

namespace silnet::aggregator {

HypothesisScore ScoreHypothesis(const EpipolarModel& model, const SilhouetteSequence& i,
                                const SilhouetteSequence& j, const std::vector<uint64_t>& frames_i,
                                const ScoringOptions& options, std::vector<double>* errors) {
  HypothesisScore score;
  errors->clear();
  const Eigen::Matrix3d f = model.Fundamental();
  const double outlier_share = 1.0 - options.quantile;
  // A passing model has at most this many outliers among all possible matches.
  const double outlier_budget = outlier_share * 2.0 * static_cast<double>(frames_i.size());
  size_t outliers = 0;
  size_t next_check = 16;
  TimedMatch matches[2];
  for (uint64_t k : frames_i) {
    ++score.frames_evaluated;
    const int n = MatchAtFrame(model, i, j, k, matches);
    for (int m = 0; m < n; ++m) {
      const double e = TransferError(f, matches[m].x_i, matches[m].XjAt(model.offset));
      errors->push_back(e);
      if (e > options.tau) ++outliers;
    }
    if (!options.early_rejection) continue;
    if (static_cast<double>(outliers) > outlier_budget) return score;
    const size_t seen = errors->size();
    if (seen >= next_check) {
      // Far more outliers so far than a passing model would show (binomial bound).
      const double p = outlier_share + 0.05;
      const double limit = p * static_cast<double>(seen) +
                           3.0 * std::sqrt(p * (1.0 - p) * static_cast<double>(seen)) + 2.0;
      if (static_cast<double>(outliers) > limit) return score;
      next_check *= 2;
    }
    if (score.frames_evaluated == 40 &&
        static_cast<double>(seen) < options.min_match_fraction * 2.0 * 40.0) {
      return score;  // the epipoles lie inside most silhouettes
    }
  }
  score.matches = errors->size();
  if (static_cast<double>(score.matches) <
          options.min_match_fraction * 2.0 * static_cast<double>(frames_i.size()) ||
      score.matches < 8) {
    return score;
  }
  const size_t kth = static_cast<size_t>(options.quantile * static_cast<double>(score.matches - 1));
  std::nth_element(errors->begin(), errors->begin() + static_cast<std::ptrdiff_t>(kth),
                   errors->end());
  score.quantile_error = (*errors)[kth];
  score.promising = score.quantile_error < options.tau;
  return score;
}

std::vector<double> MatchErrors(const Eigen::Matrix3d& f, const std::vector<TimedMatch>& matches,
                                double offset) {
  std::vector<double> errors;
  errors.reserve(matches.size());
  for (const TimedMatch& m : matches)
    errors.push_back(TransferError(f, m.x_i, m.XjAt(offset)));
  return errors;
}

std::vector<size_t> DistinctMatches(const std::vector<TimedMatch>& matches, double offset,
                                    double bin_px) {
  std::unordered_set<uint64_t> seen;
  std::vector<size_t> keep;
  for (size_t m = 0; m < matches.size(); ++m) {
    const Eigen::Vector2d xj = matches[m].XjAt(offset);
    const auto q = [&](double v) {
      return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / bin_px)) & 0xFFFF);
    };
    const uint64_t key = q(matches[m].x_i.x()) | (q(matches[m].x_i.y()) << 16) | (q(xj.x()) << 32) |
                         (q(xj.y()) << 48);
    if (seen.insert(key).second) keep.push_back(m);
  }
  return keep;
}

}  // namespace silnet::aggregator
