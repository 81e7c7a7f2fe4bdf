#pragma once
// Silhouette of a still photograph against one photograph of the empty scene, for stills
// folders without masks. The node's segmenters learn a background from a video (a running
// median or OpenCV's mixtures), which one still cannot feed, so this is their single-image
// counterpart: a pixel is foreground when its BGR distance to the background exceeds
// `min_difference`, unless it passes the node's shadow test (darker by a ratio in
// [shadow_min_ratio, shadow_max_ratio] with unchanged chromaticity, thesis B-1.1); then the
// node's clean-up (node/segmentation/mask_cleanup.h: opening, closing, small blobs removed,
// small holes filled) applies.

#include <opencv2/core/mat.hpp>

#include "node/segmentation/mask_cleanup.h"
#include "node/segmentation/segmentation_options.h"

namespace silnet::aggregator {

// Settings: the node's segmentation options, of which min_difference (the colour distance
// threshold, digital numbers), the shadow test and the clean-up are used.
struct BackgroundDifferenceOptions {
  node::SegmentationOptions node = DefaultNodeOptions();

  // The node's defaults with a threshold suited to a single background image, whose noise
  // the model cannot learn (25 DN rather than 12).
  static node::SegmentationOptions DefaultNodeOptions();
};

// The silhouette (CV_8UC1, 0/255) of `still` against `background` (both CV_8UC3, one
// size) and what clean-up did. Throws InputError if the images differ in size or type.
struct BackgroundDifference {
  cv::Mat mask;
  node::CleanupStats cleanup;
};
BackgroundDifference SegmentAgainstBackground(const cv::Mat& still, const cv::Mat& background,
                                              const BackgroundDifferenceOptions& options = {});

}  // namespace silnet::aggregator
