#pragma once
// A metric start without self-calibration (beyond the thesis): when the projective route
// cannot place three cameras, or its linear self-calibration fails, the cameras are given
// square pixels, the principal point at the image centre and one focal length shared by all,
// chosen from a log-spaced range as the one whose essential matrices agree best around the
// network (most pairs whose relative rotations close, then the smallest rotation errors;
// GlobalStart). Wrong focal lengths bend the relative rotations so that cycles do not close.
// Where no focal length closes a cycle within the rotation tolerance (strong lens distortion
// and principal points off centre bend them too), the search is repeated once with a looser
// tolerance. The bundle adjustment then frees each camera's intrinsics.

#include <string>
#include <vector>

#include "aggregator/calibration/global_start.h"

namespace silnet::aggregator {

// The focal lengths tried, as multiples of each image's larger side.
struct FocalSearchOptions {
  double min_factor = 0.35;
  double max_factor = 4.0;
  int steps = 24;
  // The global start's rotation tolerance is multiplied by this for the second search, when
  // the first finds nothing (1 = no second search).
  double fallback_tolerance_factor = 2.0;
};

// The chosen focal length and the global start it gives.
struct FocalSearchResult {
  bool ok = false;
  double factor = 0.0;               // focal length / larger image side
  std::vector<CameraModel> cameras;  // the templates with that K
  GlobalStart start;
  std::string detail;  // what was tried and chosen, or why nothing worked
};

// Searches the focal length for `templates` (id, image size) from `pairs`.
FocalSearchResult SearchCommonFocal(const std::vector<CameraModel>& templates,
                                    const std::vector<PairwiseResult>& pairs,
                                    const FocalSearchOptions& options,
                                    const GlobalStartOptions& start_options);

}  // namespace silnet::aggregator
