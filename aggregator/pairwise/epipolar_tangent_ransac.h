#pragma once
// Epipolar geometry and time offset of a camera pair from the silhouettes of moving
// subjects (thesis chapter 2): RANSAC over epipolar tangents.
//
//   hypothesis   a random pair of corresponding frames; two random tangent directions per
//                view give hypothesised epipoles; with the outer tangents of a second frame
//                pair they fix the epipolar line homography (2.3.3)
//   verification the K-quantile of the epipolar transfer errors of all frames' outer
//                tangents against the outlier threshold tau0, with early rejection (2.3.4)
//   tuning       tau0 lowered automatically from 50 px during preliminary iterations;
//                n_g = max(2 tau0, 10) promising candidates are collected (2.3.5)
//   refinement   Levenberg-Marquardt with guided matching (2.3.4), here applied to each
//                promising hypothesis as it is found (local optimisation, LO-RANSAC): the
//                thesis's strict tau0 leaves few candidates, while the refinement converges
//                from much rougher ones; solutions are kept once three candidates reach them
//                (Zhang's distance)
//   giving up    a pair without a solution stops early when no hypothesis passes the screen
//                for many rounds in a row (silhouettes that do not correspond in time)
//   offset       unsynchronised pairs sample the offset too, coarse to fine (2.5): over a
//                wide range hypotheses are verified on the slow keyframes (tolerant to an
//                offset a few frames off); the first locally optimised solution fixes the
//                offset to a frame; then all frames, offsets within +-2 frames of it, and
//                the refinement gives the sub-frame offset and its sigma
// The estimator parts (hypothesis, scoring, refinement) live in their own files; this is
// the part that drives them.

#include <optional>
#include <string>
#include <vector>

#include "aggregator/pairwise/epipolar_refinement.h"
#include "aggregator/pairwise/hypothesis_scoring.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the pairwise estimator; defaults follow the thesis. The thresholds that measure
// how rough a hypothesis may be (tau_start, screen_min, screen_max), when solutions are distinct
// (ambiguity_px) and how far silhouettes must move (min_motion_px) are pixels of a 640x480
// image; EstimatePair scales them up with larger images (ScaledToImages). The inlier
// thresholds (final_threshold, consensus_px) are segmentation noise and stay in pixels.
struct PairwiseOptions {
  double quantile = 0.75;            // K of the K-quantile test
  double tau_start = 50.0;           // initial outlier threshold tau0, pixels
  int tau_patience = 8;              // C_max of the tau0 tuning
  size_t tuning_iterations = 10000;  // preliminary iterations for tuning tau0, at most
  double final_threshold = 1.0;      // inlier threshold tau1, pixels
  size_t max_iterations = 1000000;   // sampling rounds in all
  size_t min_candidates = 10;        // n_g is at least this
  bool synchronized = false;         // cameras share a clock: offset 0
  double offset_min = -30.0;         // offset search range (frames), when unsynchronised
  double offset_max = 30.0;
  std::optional<double> offset_prior;  // e.g. from node timestamps: search prior +- prior_sigma * 3
  double prior_sigma = 2.0;
  double consensus_px = 2.0;   // solutions agree if their Zhang distance is below this
  size_t agreeing = 3;         // stop once this many candidates reach the same solution
  double ambiguity_px = 10.0;  // solutions further apart than this are distinct
  double alternative_support =
      0.6;  // distinct solutions kept with this share of the best's inliers
  // Local optimisation (beyond the thesis): a hypothesis passes the screen when its K-quantile
  // is below screen_factor * tau0 (at least screen_min px), is then refined on a sample of
  // local_frames frames, and counts when at least local_support of the possible frontier
  // correspondences of that sample fit within local_fit_px; only such solutions are fully
  // refined. Silhouettes that still carry lens distortion fit no pinhole F that closely: on
  // the Utrecht capture (k1 about -0.37) the best local fits of converging pairs reached 28-30 %
  // within 2 px, and 2 of 6 pairs failed on most seeds.
  double screen_factor = 3.0;
  double screen_min = 15.0;
  double screen_max = 60.0;
  size_t local_frames = 120;
  double local_support = 0.3;
  double local_fit_px = 2.0;
  static constexpr double kDistortedLocalFitPx = 3.0;  // for silhouettes with lens distortion
  size_t max_local_optimisations = 300;
  // Giving up on pairs that cannot converge: pairs that converge went at most about 25000
  // sampling rounds without a hypothesis passing the screen (simulated rings and domes, the
  // Utrecht capture); silhouettes that do not correspond in time, 35000 per hypothesis passing.
  size_t give_up_iterations = 50000;  // rounds in a row without one: give up (0 = never)
  bool allow_warmup = false;
  double min_motion_px = 5.0;  // silhouettes moving less than this: too little motion
  uint64_t seed = 1;

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// The image size the pixel thresholds of PairwiseOptions are set for.
inline constexpr int kReferenceWidth = 640, kReferenceHeight = 480;

// `options` with its image-size-dependent thresholds (see PairwiseOptions) multiplied by the
// pair's mean image size (width + height) over 640x480's, when that is above 1; unchanged for
// images of that size or smaller.
PairwiseOptions ScaledToImages(const PairwiseOptions& options, int width_i, int height_i,
                               int width_j, int height_j);

// Why a pair's geometry is not trusted. kAmbiguous: several distinct solutions of similar
// support, or one that too few candidates confirmed; the network stage may pick one of them
// by its consistency with the other pairs (PairwiseResult::alternatives holds the others).
enum class PairStatus { kOk, kDegenerate, kFailed, kAmbiguous };
const char* ToString(PairStatus status);

// One distinct solution of a pair's RANSAC: its geometry and how well it is supported.
struct PairCandidate {
  EpipolarModel model;
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  double offset = 0.0;
  double offset_sigma = 0.0;
  size_t inliers = 0;
  double residual_rms = 0.0;
  size_t support = 0;  // locally optimised candidates that reached it
  std::vector<TimedMatch> inlier_matches;
};

// The outcome for one camera pair.
struct PairwiseResult {
  std::string camera_i, camera_j;
  PairStatus status = PairStatus::kFailed;
  std::string reason;  // empty when ok
  EpipolarModel model;
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  double offset = 0.0;  // frames: frame k of i meets frame k + offset of j
  double offset_sigma = 0.0;
  size_t inliers = 0;                    // distinct frontier correspondences within 1 px
  double residual_rms = 0.0;             // pixels
  double spread_score = 0.0;             // thesis 3.2.3: sum of squared distances to the centroids
  double epipole_inside_fraction = 0.0;  // frames whose hull contains an epipole (either view)
  double tau0 = 0.0;
  size_t iterations = 0;
  size_t candidates = 0;
  size_t candidates_refined = 0;
  size_t candidates_agreeing = 0;
  // The best local optimisation's inliers as a share of its possible frontier correspondences
  // (a solution needs PairwiseOptions::local_support).
  double best_local_support = 0.0;
  double seconds = 0.0;
  std::vector<TimedMatch> inlier_matches;
  // Other distinct solutions that explain nearly as much (ambiguous pairs), best first.
  std::vector<PairCandidate> alternatives;

  // The reported solution as a candidate.
  PairCandidate Chosen() const;
  // Makes `candidate` the reported solution (status and reason unchanged).
  void Adopt(PairCandidate candidate);
  // Makes `candidate` the reported solution (the previous one becomes an alternative) and
  // marks the pair ok with `reason` saying why it was chosen.
  void Choose(size_t alternative, const std::string& why);
};

// Estimates the epipolar geometry (and offset) of cameras i and j.
PairwiseResult EstimatePair(const SilhouetteSequence& i, const SilhouetteSequence& j,
                            const PairwiseOptions& options, Progress* progress = nullptr);

}  // namespace silnet::aggregator
