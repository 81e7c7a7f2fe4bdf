// Giving up on pairs that cannot converge: the RANSAC driver stops after a run of rounds
// without a promising model, and the pairwise estimator reports why; a pair that converges is
// not affected. Outcomes are asserted on rounds counted, never on seconds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "aggregator/pairwise/ransac_driver.h"
#include "tests/aggregator/pairwise_eval.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

// An estimator whose models are promising only at the rounds listed (1-based).
struct ScriptedEstimator {
  using Model = size_t;
  struct Score {
    bool promising = false;
  };
  std::vector<size_t> promising_rounds;
  size_t round = 0;

  void Hypothesize(std::mt19937_64&, std::vector<Model>* models) { models->push_back(++round); }
  Score Verify(const Model& model) const {
    return {std::find(promising_rounds.begin(), promising_rounds.end(), model) !=
            promising_rounds.end()};
  }
};

TEST(RansacDriver, StopsAfterARunOfDryRounds) {
  ScriptedEstimator estimator;
  estimator.promising_rounds = {500, 1200};
  RansacLimits limits;
  limits.max_iterations = 100000;
  limits.candidates = 100;
  limits.max_dry_rounds = 1000;
  std::mt19937_64 rng(1);
  const auto report = RunRansac(estimator, limits, rng);
  EXPECT_TRUE(report.dry);
  EXPECT_EQ(report.candidates.size(), 2u);
  EXPECT_EQ(report.iterations, 2200u);  // 1000 rounds after the last candidate

  ScriptedEstimator never;
  limits.max_dry_rounds = 0;  // off: runs to the round limit
  limits.max_iterations = 5000;
  const auto full = RunRansac(never, limits, rng);
  EXPECT_FALSE(full.dry);
  EXPECT_EQ(full.iterations, 5000u);
}

// Sequence `s` with its silhouettes shuffled over its frames: nothing corresponds in time.
SilhouetteSequence ShuffledInTime(SilhouetteSequence s, uint64_t seed) {
  std::vector<SilhouetteHull> hulls;
  for (const SilhouetteFrame& f : s.frames)
    hulls.push_back(f.hull);
  std::mt19937_64 rng(seed);
  std::shuffle(hulls.begin(), hulls.end(), rng);
  for (size_t k = 0; k < s.frames.size(); ++k)
    s.frames[k].hull = std::move(hulls[k]);
  s.Index();
  return s;
}

testing::SimCapture FourCameras() {
  sim::CameraNetworkOptions network;
  network.cameras = 4;
  network.max_offset = 10.0;
  network.seed = 1;
  sim::SceneOptions scene;
  scene.seed = 1;
  return testing::MakeSimCapture(network, scene, 400);
}

PairwiseOptions Unsynchronised() {
  PairwiseOptions options;
  options.offset_min = -35;
  options.offset_max = 35;
  return options;
}

TEST(PairwiseEarlyStop, SilhouettesShuffledInTimeAreGivenUpEarly) {
  const testing::SimCapture capture = FourCameras();
  const PairwiseOptions options = Unsynchronised();
  for (const size_t j : {1, 3}) {
    const SilhouetteSequence shuffled = ShuffledInTime(capture.sequences[j], j);
    const PairwiseResult r = EstimatePair(capture.sequences[0], shuffled, options);
    std::printf("0-%zu shuffled: %s: %s (%.2f s)\n", j, ToString(r.status), r.reason.c_str(),
                r.seconds);
    EXPECT_EQ(r.status, PairStatus::kFailed);
    EXPECT_NE(r.reason.find("gave up: no hypothesis passed the screen"), std::string::npos)
        << r.reason;
    // Without giving up such a pair spends the whole budget (1000000 rounds; the reason was
    // "no hypothesis converged in 1000000 iterations (1 screened)").
    EXPECT_LT(r.iterations, options.max_iterations / 5);
    EXPECT_LT(r.candidates, 10u);
  }
  // Turned off, the same pair runs to the end of its budget.
  PairwiseOptions never = options;
  never.give_up_iterations = 0;
  never.max_iterations = 150000;
  const PairwiseResult full =
      EstimatePair(capture.sequences[0], ShuffledInTime(capture.sequences[1], 1), never);
  EXPECT_EQ(full.status, PairStatus::kFailed);
  EXPECT_EQ(full.iterations, never.max_iterations);
  EXPECT_NE(full.reason.find("no hypothesis converged"), std::string::npos) << full.reason;
}

TEST(PairwiseEarlyStop, APairThatConvergesIsUnaffected) {
  const testing::SimCapture capture = FourCameras();
  const PairwiseOptions options = Unsynchronised();
  PairwiseOptions never = options;
  never.give_up_iterations = 0;
  for (const size_t j : {1, 2}) {
    const PairwiseResult r = EstimatePair(capture.sequences[0], capture.sequences[j], options);
    const PairwiseResult reference =
        EstimatePair(capture.sequences[0], capture.sequences[j], never);
    const testing::PairEvaluation e = testing::Evaluate(capture, 0, j, r, 400);
    std::printf("0-%zu: %s, %zu inliers, %zu iterations, epipolar %.2f px, offset error %.3f\n", j,
                ToString(r.status), r.inliers, r.iterations, e.median_epipolar_px, e.offset_error);
    EXPECT_EQ(r.status, PairStatus::kOk) << r.reason;
    EXPECT_LE(e.median_epipolar_px, 1.0);
    EXPECT_LE(e.offset_error, 0.2);
    // The same search, round for round.
    EXPECT_EQ(r.status, reference.status);
    EXPECT_EQ(r.iterations, reference.iterations);
    EXPECT_EQ(r.inliers, reference.inliers);
    EXPECT_DOUBLE_EQ(r.offset, reference.offset);
  }
}

TEST(PairwiseEarlyStop, OptionsAreValidated) {
  PairwiseOptions options;
  EXPECT_TRUE(options.Validate().empty());
  options.give_up_iterations = 10;
  EXPECT_NE(options.Validate().find("give_up_iterations"), std::string::npos);
  options.give_up_iterations = 0;
  EXPECT_TRUE(options.Validate().empty());
  options.local_support = 0.0;
  EXPECT_FALSE(options.Validate().empty());
}

}  // namespace
}  // namespace silnet::aggregator
