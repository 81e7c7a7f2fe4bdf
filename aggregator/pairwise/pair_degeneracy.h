#pragma once
// Degeneracy checks of an estimated pair (DESIGN "degeneracy detection with a reason"): a
// geometry fitted to too few, too clustered or too planar frontier points, or with
// epipoles inside the silhouettes most of the time, is reported, never silently used.

#include <string>
#include <vector>

#include "aggregator/pairwise/frame_pairing.h"

namespace silnet::aggregator {

// Facts about the support of an estimate.
struct SupportDiagnosis {
  double epipole_inside_fraction = 0.0;   // usable frames whose hull contains an epipole
  double spread_i = 0.0, spread_j = 0.0;  // RMS distance of the inliers to their centroid, px
  double spread_score = 0.0;              // thesis 3.2.3 inlier spread score
  double planar_fraction = 0.0;           // inliers a homography explains within 1.5 px
  std::string reason;                     // empty if nothing is wrong
};

// Thresholds of the checks.
struct DegeneracyLimits {
  size_t min_inliers = 30;
  double max_epipole_inside = 0.8;
  double min_spread_fraction = 0.03;  // of the image diagonal
  double max_planar_fraction = 0.9;
};

// Diagnoses the support of `model` on the pair.
SupportDiagnosis DiagnoseSupport(const EpipolarModel& model, const std::vector<TimedMatch>& inliers,
                                 const SilhouetteSequence& i, const SilhouetteSequence& j,
                                 const DegeneracyLimits& limits = {});

}  // namespace silnet::aggregator
