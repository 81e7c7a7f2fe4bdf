#pragma once
// Which frames of two cameras are compared under a time offset, and the frontier point
// correspondences a model gives on them. Frame k of camera i meets camera j at the
// (fractional) frame k + offset; view j's tangents are interpolated between its two
// neighbouring frames.

#include <cstdint>
#include <vector>

#include "aggregator/pairwise/frontier_matching.h"
#include "aggregator/pairwise/silhouette_sequence.h"

namespace silnet::aggregator {

// A frontier correspondence in time: the touch point in view i at frame k, and in view j
// the touch points at frames a and a + 1 (equal when the time falls on a frame).
struct TimedMatch {
  Eigen::Vector2d x_i;
  Eigen::Vector2d x_j_a;
  Eigen::Vector2d x_j_b;
  uint64_t frame_i = 0;
  uint64_t frame_j = 0;  // a
  int side = 0;          // which tangent of view i (OuterTangents index)
  int partner = 0;       // which tangent of view j

  // The fraction of the way from frame a to a + 1 at time offset `offset`.
  double Fraction(double offset) const {
    return static_cast<double>(frame_i) + offset - static_cast<double>(frame_j);
  }
  // View j's touch point at time offset `offset`.
  Eigen::Vector2d XjAt(double offset) const {
    const double f = Fraction(offset);
    return (1.0 - f) * x_j_a + f * x_j_b;
  }
};

// View j's usable hulls bracketing the time of frame k of i: a at floor(time), b the next
// frame (fraction in [0, 1)); false if a is missing, or b is missing for a fraction above
// zero. On an exact frame time b is the next frame when it is usable (so the offset keeps a
// gradient), else a again.
bool BracketInJ(const SilhouetteSequence& j, uint64_t frame_i, double offset,
                const SilhouetteFrame** a, const SilhouetteFrame** b, double* fraction);

// The frontier correspondences of `model` at frame k of camera i (up to two). With
// `with_next`, view j's touch points are also found at the next frame on exact frame times
// (refinement needs them; scoring does not).
int MatchAtFrame(const EpipolarModel& model, const SilhouetteSequence& i,
                 const SilhouetteSequence& j, uint64_t frame_i, TimedMatch out[2],
                 bool with_next = false);

// All frontier correspondences of `model` over the given frames of camera i.
std::vector<TimedMatch> MatchAllFrames(const EpipolarModel& model, const SilhouetteSequence& i,
                                       const SilhouetteSequence& j,
                                       const std::vector<uint64_t>& frames_i);

// The usable frame indices of a sequence.
std::vector<uint64_t> UsableFrames(const SilhouetteSequence& sequence);

}  // namespace silnet::aggregator
