#pragma once
// The true segments of each cone strip (thesis 6.5, "identifying the true segments"): of the
// view-edge segments a viewing ray leaves on the visual hull only one holds the rim point.
// Per contour loop, the segments of successive rays form the rim graph; an edge joins two
// segments of successive rays, weighted w(u) + w(v) where both border one piece of the cone
// face between the rays (w = 1 - photo-consistency of the segment's best point), and a fixed
// discontinuity cost K elsewhere; the shortest cycle through the loop's rays picks one segment
// per ray. A larger K gives a more continuous rim; a discontinuity is a T-junction's ray.

#include <utility>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/stereo/hull_view_edges.h"

namespace silnet::aggregator {

// The chosen segments.
struct TrueSegments {
  std::vector<bool> is_true;  // per segment of HullViewEdges::segments
  // Successive true segments (indexes into the segments, in loop order) that share no face
  // piece: the rim is discontinuous between them and the strip needs a connecting curve.
  std::vector<std::pair<int, int>> breaks;
  // The face pieces successive true segments share: the strips' parts between true segments
  // (a piece only one true segment borders lies beyond the end of its part of the strip).
  std::vector<int> strip_pieces;
  size_t loops = 0;  // contour loops with at least one segment
};

// Chooses one segment per ray that has any, on every contour loop of every view.
// `segment_weight` holds w(u) >= 0 per segment; `discontinuity_cost` is K (> the weights).
TrueSegments ChooseTrueSegments(const HullViewEdges& edges, const std::vector<ConePlane>& planes,
                                const std::vector<double>& segment_weight,
                                double discontinuity_cost);

}  // namespace silnet::aggregator
