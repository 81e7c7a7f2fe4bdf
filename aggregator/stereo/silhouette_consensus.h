#pragma once
// Weak silhouette evidence confirmed by the other views (beyond the thesis, which took its
// silhouettes as given): a node marks the pixels beside a still's silhouette that differ from
// the background by less than its threshold but more than noise (node/segmentation/
// weak_silhouette.h). Such a pixel is kept where its viewing ray meets the visual hull of the
// other views' silhouettes taken with their own weak pixels, and dropped elsewhere: a thin part
// that is weak in several views (a dark pole against a dark wall) confirms itself across them,
// while clutter beside one view's silhouette has to meet every other view's silhouette or weak
// evidence in one point. Under exact silhouette constraints a missing silhouette pixel is a
// hole through the model while an extra one only widens the hull, so evidence the other views
// support is worth taking (docs/PERFORMANCE.md: the live job's statue 1.66 -> 1.42 footprints
// of accuracy; with weak pixels confirmed by weak pixels too, the pole's top is kept).

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
// the other views' visual hull (their masks' 255 and weak pixels), 0 elsewhere; the masks are 0/255
// afterwards. Needs at least three views to confirm anything (with fewer, weak pixels are
// dropped). The hull is sampled along each ray at a step of a thousandth of the subject's size.
SilhouetteConsensus ResolveWeakSilhouettes(std::vector<StereoView>* views, uint8_t weak);

}  // namespace silnet::aggregator
