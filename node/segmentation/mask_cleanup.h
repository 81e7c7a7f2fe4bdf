#pragma once
// Clean-up of raw foreground masks (thesis B-1.1): morphological opening and closing,
// removal of small blobs, filling of small holes; and an optional graph-cut refinement of
// the silhouette boundary.

#include <opencv2/core/mat.hpp>

#include "node/segmentation/segmentation_options.h"

namespace silnet::node {

// What clean-up found.
struct CleanupStats {
  int blobs = 0;          // connected components kept
  int blobs_removed = 0;  // components smaller than min_blob_area
  int holes_filled = 0;
};

// Cleans a CV_8UC1 0/255 mask in place.
CleanupStats CleanMask(cv::Mat* mask, const SegmentationOptions& options);

// Refines the boundary of `mask` with OpenCV's GrabCut (graph cut on colour models) in a
// band of `band` pixels around it; pixels further inside or outside keep their label.
void RefineWithGraphCut(const cv::Mat& frame, cv::Mat* mask, int band);

}  // namespace silnet::node
