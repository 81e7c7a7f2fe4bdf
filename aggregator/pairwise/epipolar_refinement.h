#pragma once
// Refinement of a promising epipolar hypothesis (thesis 2.3.4): Levenberg-Marquardt (Ceres)
// on the symmetric epipolar distance of the frontier correspondences, in the estimator's own
// parameters — both epipoles on the unit sphere, the line homography up to scale and, for
// unsynchronised cameras, the sub-frame time offset — alternated with guided matching: the
// frontier points are recomputed from the current epipoles and the inliers re-selected,
// until the inlier set stops changing.

#include <cstddef>
#include <random>
#include <vector>

#include "aggregator/pairwise/frame_pairing.h"

namespace silnet::aggregator {

// Settings of the refinement.
struct RefinementOptions {
  double initial_threshold = 10.0;  // inlier threshold of the first round, pixels
  double min_threshold = 1.0;       // the adaptive threshold never goes below this
  double final_threshold = 1.0;     // inliers reported at the end (thesis: 1 pixel)
  int max_rounds = 8;
  size_t max_matches = 800;  // distinct inliers used per solve (a random subset)
  bool refine_offset = false;
  double max_offset_step = 2.0;  // frames the offset may move in one round
  // Give up after the second round if fewer than this fraction of the possible frontier
  // correspondences (two per frame) are inliers (0 = never).
  double abort_fraction = 0.0;
  bool estimate_offset_sigma = false;  // jackknife the offset at the end (costs a little)
  // Added in quadrature to the jackknife sigma: the error the measurements cannot reveal
  // (tangent interpolation, pixel sampling); measured on simulated data, about 0.01 frame.
  double offset_sigma_floor = 0.015;
};

// A refined model and its support.
struct RefinedModel {
  EpipolarModel model;
  size_t inliers = 0;         // distinct matches within final_threshold
  double rms_error = 0.0;     // RMS transfer error of those inliers, pixels
  double offset_sigma = 0.0;  // standard deviation of the offset (frames), if refined: a
                              // jackknife over time blocks (neighbouring frames are not
                              // independent, so the least-squares covariance is too small)
  std::vector<TimedMatch> inlier_matches;
  int rounds = 0;
  bool valid = false;
};

// The jackknife standard deviation of the offset: the offset re-fitted alone (epipoles and
// homography fixed) leaving out each of `blocks` consecutive blocks of frames in turn.
double OffsetJackknifeSigma(const EpipolarModel& model, const std::vector<TimedMatch>& matches,
                            int blocks = 10);

// Refines `start` using the frontier correspondences over `frames_i` of camera i.
RefinedModel RefineEpipolarModel(const EpipolarModel& start, const SilhouetteSequence& i,
                                 const SilhouetteSequence& j, const std::vector<uint64_t>& frames_i,
                                 const RefinementOptions& options, std::mt19937_64* rng);

}  // namespace silnet::aggregator
