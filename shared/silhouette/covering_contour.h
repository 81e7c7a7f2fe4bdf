#pragma once
// Conservative simplification of a silhouette's traced outline rings, so the polygons cover
// the silhouette's pixel centres (the visual hull built from them misses almost none of its
// pixels).
//
// A one-sided Douglas-Peucker: the simplified ring keeps a subset of the outline points, and
// the chord that replaces a stretch of outline is split (at its outline point farthest out
// when a pixel centre is too close, farthest in when a background centre is too far inside)
// until
//   * the boundary pixel centres of the stretch (and one either side) lie at least
//     `margin_px` inside the chord,
//   * the background pixel centres next to the stretch lie at most `background_slack_px`
//     inside it,
// and then, over a few rounds, the chords of all rings of the silhouette that come closer than
// `clearance_px` to a non-adjacent chord (across a narrow background gap or a thin hole: the
// self-crossings) are split at their outline point farthest from the chord and refined again.
// A stretch of a single outline step is never split: there the conditions hold as far as the
// traced outline itself keeps them. The conditions are local; tests check on random blobs,
// holes and narrow gaps that every foreground pixel centre ends up inside.

#include <Eigen/Core>
#include <vector>

namespace silnet {

// One traced ring: the boundary pixel centres it passes through and, index for index, the
// outline points derived from them (outside the centres, possibly smoothed). Oriented with the
// silhouette on the left: outer rings positive (RingArea > 0), holes negative.
// `background` holds, two per index (in either order), background pixel centres next to that
// boundary pixel on the outline's side (NaN where there is none), or empty (no background
// condition).
struct TracedRing {
  std::vector<Eigen::Vector2f> centres;
  std::vector<Eigen::Vector2f> outline;
  std::vector<Eigen::Vector2f> background;
};

// Settings of the covering simplification.
struct CoveringOptions {
  double margin_px = 0.1;      // boundary pixel centres lie at least this far inside their edge
  double clearance_px = 0.05;  // closest approach allowed between non-adjacent edges
  // Background pixel centres next to a stretch may lie this far inside its edge (pixels): the
  // larger, the fewer edges and the more background the outline takes in.
  double background_slack_px = 0.15;
  int max_rounds = 40;  // rounds of splitting close edges; what is left close stays so
};

// Simplifies all rings of one silhouette together (their edges must not cross one another).
// Returns one ring per input ring, same order and orientation, made of its outline points
// (repeated points and points where the ring runs straight on dropped); a ring with fewer
// than four points keeps all of them.
std::vector<std::vector<Eigen::Vector2f>> SimplifyCovering(const std::vector<TracedRing>& rings,
                                                           const CoveringOptions& options);

}  // namespace silnet
