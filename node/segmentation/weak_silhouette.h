#pragma once
// Weak evidence beside a still's silhouette, for the aggregator to confirm with the other
// views: pixels next to the silhouette that differ from the background by less than the
// segmentation's threshold but clearly more than noise (a dark pole against a dark wall, the
// rim of a camouflaged part). A single view cannot tell them from noise or a soft shadow; the
// other views' silhouettes can (aggregator/stereo/silhouette_consensus.h). They are marked
// with kWeakSilhouette, below the 128 that readers threshold masks at, so a reader that does
// not know them sees plain background.

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "node/segmentation/segmentation_options.h"

namespace silnet::node {

// The mask value of a weak candidate.
inline constexpr uint8_t kWeakSilhouette = 64;

// What counts as weak evidence.
struct WeakSilhouetteOptions {
  double min_difference = 6.0;  // colour distance after a 3x3 Gaussian blur, digital numbers
};

// Marks the background pixels of `mask` (CV_8UC1, 255 silhouette, 0 background) that are
// weak evidence of the subject against `background` in `still` (CV_8UC3, the mask's size) and
// connected (8-neighbourhood) to the silhouette through such pixels, with kWeakSilhouette.
// The difference is taken after a 3x3 Gaussian blur over the pixels outside the silhouette
// only, so a contrasting outline does not make its outer neighbours evidence. Pixels that look
// like a shadow by the segmentation's colour test (shadow_texture.h) are not evidence, nor are
// the non-zero pixels of `excluded` (CV_8UC1, the mask's size; may be null: e.g. outline
// pixels already judged background by their colour). Returns how many.
int MarkWeakSilhouette(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                       const SegmentationOptions& segmentation,
                       const WeakSilhouetteOptions& options = {},
                       const cv::Mat* excluded = nullptr);

}  // namespace silnet::node
