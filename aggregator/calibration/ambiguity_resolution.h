#pragma once
// Picks, for each ambiguous camera pair, the solution consistent with the rest of the network
// (beyond the thesis, which drops such pairs): a pair whose RANSAC reached several distinct
// solutions of similar support, or one solution too few candidates confirmed, is checked
// against every third camera linked to both of its cameras by trusted pairs. The candidate
// whose fundamental matrix agrees with those pairs (TripletInconsistency) is kept when it
// agrees well and clearly better than the others; the pair then counts as trusted and can
// resolve further pairs. Pairs no triplet can decide stay ambiguous.

#include <string>
#include <vector>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Thresholds of the resolution.
struct AmbiguityOptions {
  double max_inconsistency_px = 4.0;  // a candidate's median triplet residual at most this
  double min_ratio = 3.0;  // the next candidate's residual at least this multiple of the best's
};

// What was decided for one ambiguous pair.
struct AmbiguityDecision {
  size_t pair = 0;  // index into the pairs
  bool resolved = false;
  std::vector<double>
      residual_px;  // median triplet residual of each candidate (chosen first before)
  std::string note;
};

// Resolves the ambiguous pairs among `pairs` in place (cameras named by id in `cameras`, whose
// image sizes normalise the residuals); returns one decision per ambiguous pair.
std::vector<AmbiguityDecision> ResolveAmbiguousPairs(const std::vector<CameraModel>& cameras,
                                                     std::vector<PairwiseResult>* pairs,
                                                     const AmbiguityOptions& options = {});

}  // namespace silnet::aggregator
