#pragma once
// Weak silhouette evidence confirmed by the other views (beyond the thesis, which took its
// silhouettes as given): a node marks the pixels beside a still's silhouette that differ from
// the background by less than its threshold but more than noise (node/segmentation/
// weak_silhouette.h). Such a pixel is kept where its viewing ray meets the visual hull of the
// other views' silhouettes, and dropped elsewhere. Under exact silhouette constraints a missing
// silhouette pixel is a hole through the model while an extra one only widens the hull, so
// evidence the other views support is worth taking: on the live job's statue 1.66 -> 1.42
// footprints of accuracy (docs/PERFORMANCE.md). Taking all of it did as well on these
// simulated statues (1.30 and 1.76 fp against 1.42 and 1.78) but would take whatever clutter a
// real scene puts beside a silhouette.

#include <cstddef>
#include <vector>

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// What the check did over all views.
struct SilhouetteConsensus {
  size_t candidates = 0;  // weak pixels
  size_t kept = 0;        // of which the other views support
};

// Resolves the weak pixels (value `weak`) of every view's mask: 255 where the pixel's ray meets
// the other views' visual hull (their masks' 255 pixels), 0 elsewhere; the masks are 0/255
// afterwards. Needs at least three views to confirm anything (with fewer, weak pixels are
// dropped). The hull is sampled along each ray at a step of a thousandth of the subject's size.
SilhouetteConsensus ResolveWeakSilhouettes(std::vector<StereoView>* views, uint8_t weak);

}  // namespace silnet::aggregator
