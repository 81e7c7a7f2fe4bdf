#pragma once
// Silhouette of a still photograph against one photograph of the empty scene: for the
// node's stills taken by a still stream of their own, and for stills folders without masks. The
// node's segmenters learn a background from a video (a running median or OpenCV's mixtures), which
// one still cannot feed, so this is their single-image counterpart: a pixel is foreground when its
// BGR distance to the background exceeds `min_difference`, unless it passes the node's shadow test
// (darker by a ratio in [shadow_min_ratio, shadow_max_ratio] with unchanged chromaticity and the
// background's texture, thesis B-1.1, shadow_texture.h); then the node's clean-up
// (node/segmentation/mask_cleanup.h: opening, closing, small blobs removed, small holes filled)
// applies, holes that show the subject's texture rather than the background's are filled
// (camouflaged_holes.h), and outline pixels the subject covers less than half of are dropped
// (outline_coverage.h).

#include <opencv2/core/mat.hpp>

#include "node/segmentation/camouflaged_holes.h"
#include "node/segmentation/mask_cleanup.h"
#include "node/segmentation/outline_coverage.h"
#include "node/segmentation/segmentation_options.h"
#include "node/segmentation/weak_silhouette.h"

namespace silnet::node {

// Settings: the node's segmentation options, of which min_difference (the colour distance
// threshold, digital numbers), the shadow test and the clean-up are used. The node's defaults
// hold here too: with the shadow test's texture check, 12 DN separates a statue from a wall of
// nearly its colour (IoU 0.96-0.99 against the exact silhouette on the simulator's statue,
// 1280x960) where 25 DN lost whole limbs (0.87-0.90).
struct BackgroundDifferenceOptions {
  SegmentationOptions node;
  bool fill_camouflaged_holes = true;
  CamouflageOptions camouflage;
  bool trim_partly_covered_outline = true;
  OutlineCoverageOptions outline;
  // Mark weak evidence beside the silhouette with kWeakSilhouette (weak_silhouette.h) for a
  // multi-view check downstream; off: the mask is 0/255.
  bool mark_weak_silhouette = false;
  WeakSilhouetteOptions weak;
};

// The silhouette (CV_8UC1, 0/255) of `still` against `background` (both CV_8UC3, one
// size) and what clean-up did. Throws InputError if the images differ in size or type.
struct BackgroundDifference {
  cv::Mat mask;
  CleanupStats cleanup;
  int camouflaged_holes_filled = 0;
  int outline_pixels_trimmed = 0;  // partly covered, dropped
  int weak_pixels = 0;             // marked kWeakSilhouette
};
BackgroundDifference SegmentAgainstBackground(const cv::Mat& still, const cv::Mat& background,
                                              const BackgroundDifferenceOptions& options = {});

}  // namespace silnet::node
