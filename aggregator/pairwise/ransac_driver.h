#pragma once
// One RANSAC driver for silnet's estimators (in the manner of COLMAP's): it draws
// hypotheses from an estimator, verifies each, and collects the promising ones until it
// has enough or runs out of iterations. The estimator supplies:
//   using Model = ...;  using Score = ...;   (Score has a bool `promising`)
//   void Hypothesize(std::mt19937_64& rng, std::vector<Model>* models);
//   Score Verify(const Model& model);

#include <cstddef>
#include <functional>
#include <random>
#include <vector>

#include "shared/util/progress.h"

namespace silnet::aggregator {

// When to stop.
struct RansacLimits {
  size_t max_iterations = 1000000;  // sampling rounds (one may give several models)
  size_t candidates = 10;           // promising models wanted
  size_t max_dry_rounds = 0;        // stop after this many rounds in a row without a promising
                                    // model (0 = never)
};

// A promising model with its score.
template <class Model, class Score>
struct RansacCandidate {
  Model model;
  Score score;
};

// What the driver found.
template <class Model, class Score>
struct RansacReport {
  std::vector<RansacCandidate<Model, Score>> candidates;
  size_t iterations = 0;
  size_t models_verified = 0;
  bool cancelled = false;
  bool dry = false;  // stopped by RansacLimits::max_dry_rounds
};

// Runs the estimator until `limits` (rounds in all, candidates, rounds in a row without a
// candidate), cancellation (polled through `progress`, if given), or until `on_candidate` —
// called with each promising model as it is found, for local optimisation — returns true.
template <class Estimator>
RansacReport<typename Estimator::Model, typename Estimator::Score> RunRansac(
    Estimator& estimator, const RansacLimits& limits, std::mt19937_64& rng,
    const Progress* progress = nullptr,
    const std::function<
        bool(const RansacCandidate<typename Estimator::Model, typename Estimator::Score>&)>&
        on_candidate = {}) {
  RansacReport<typename Estimator::Model, typename Estimator::Score> report;
  std::vector<typename Estimator::Model> models;
  size_t last_candidate = 0;  // the round of the latest candidate (0 = none yet)
  while (report.iterations < limits.max_iterations &&
         report.candidates.size() < limits.candidates) {
    if (progress != nullptr && (report.iterations & 1023) == 0 && progress->cancelled()) {
      report.cancelled = true;
      break;
    }
    if (limits.max_dry_rounds > 0 && report.iterations - last_candidate >= limits.max_dry_rounds) {
      report.dry = true;
      break;
    }
    ++report.iterations;
    models.clear();
    estimator.Hypothesize(rng, &models);
    for (const auto& model : models) {
      ++report.models_verified;
      auto score = estimator.Verify(model);
      if (!score.promising) continue;
      report.candidates.push_back({model, score});
      last_candidate = report.iterations;
      if (on_candidate && on_candidate(report.candidates.back())) return report;
    }
  }
  return report;
}

}  // namespace silnet::aggregator
