#pragma once
// Ground-truth evaluation of pairwise estimates on simulated captures.

#include <random>
#include <vector>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator::testing {

// How an estimate compares with the truth.
struct PairEvaluation {
  double median_epipolar_px = 0.0;  // symmetric epipolar distance of true correspondences
  double offset_error = 0.0;        // frames
  double true_offset = 0.0;
  double true_epipole_inside = 0.0;  // fraction of frames with a true epipole inside a hull
};

// Median symmetric epipolar distance of `f` on projections of the subject's surface
// (random times, points seen inside both images).
double MedianEpipolarDistance(const SimCapture& capture, size_t i, size_t j,
                              const Eigen::Matrix3d& f, int frames, std::mt19937_64& rng);

// The fraction of usable frames in which the true epipole of the other camera lies inside
// the silhouette's hull, in either view.
double TrueEpipoleInsideFraction(const SimCapture& capture, size_t i, size_t j);

PairEvaluation Evaluate(const SimCapture& capture, size_t i, size_t j, const PairwiseResult& result,
                        int frames);

}  // namespace silnet::aggregator::testing
