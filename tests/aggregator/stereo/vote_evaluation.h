#pragma once
// Test helpers: a photo-consistency vote lattice against a simulated subject's true surface
// (gt_surface.ply points): where the votes lie and where the maxima along viewing rays lie.

#include <Eigen/Core>
#include <vector>

#include "aggregator/hulls/nearest_point.h"
#include "aggregator/stereo/photo_consistency.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator::testing {

// The library's k-d tree (aggregator/hulls/nearest_point.h), under the helpers' name.
using ::silnet::aggregator::NearestPoint;

// Share of all votes in cells whose centre lies within `distance` of the truth, for each of
// `distances` (metres).
std::vector<double> VoteShareWithin(const VoteVolume& volume, const NearestPoint& truth,
                                    const std::vector<double>& distances);

// The cell with the most votes (at least `min_votes`) along the viewing ray of every
// `step`-th silhouette pixel of `view`, stepping half a cell; with the depth of the first
// cell of `solid` (per cell of `volume`, non-zero = inside, e.g. the rasterised hull) on the
// same ray. Rays without such a cell are left out.
struct RayMaximum {
  Eigen::Vector3d cell_centre;  // of the maximum
  Eigen::Vector3d solid_entry;  // first point of the ray inside `solid`
  bool has_solid_entry = false;
};
std::vector<RayMaximum> RayMaxima(const VoteVolume& volume, const std::vector<uint8_t>& solid,
                                  const StereoView& view, int step, float min_votes);

}  // namespace silnet::aggregator::testing
