#pragma once
// Slow and fast keyframes for the coarse-to-fine offset search (thesis 2.5.1). Without
// known epipoles the motion of frontier points is judged heuristically: for epipoles at
// infinity in four canonical directions (E, NE, N, NW) the extremal tangent points of each
// frame's hull are followed over time; frames where they barely move are "slow" (good for
// a coarse alignment), frames where they move most are "fast" (good for an accurate one).

#include <cstdint>
#include <vector>

#include "aggregator/pairwise/silhouette_sequence.h"

namespace silnet::aggregator {

// Keyframes of one sequence, ascending.
struct Keyframes {
  std::vector<uint64_t> slow;
  std::vector<uint64_t> fast;
};

// Picks `fraction` of the usable frames (at least `minimum`) as slow and as fast keyframes.
Keyframes SelectKeyframes(const SilhouetteSequence& sequence, double fraction = 0.2,
                          size_t minimum = 40);

}  // namespace silnet::aggregator
