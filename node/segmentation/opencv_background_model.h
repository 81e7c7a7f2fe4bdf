#pragma once
// OpenCV's adaptive background subtractors (MOG2, KNN) as background models, with their
// shadow detection, and the trivial model for precomputed silhouettes.

#include <opencv2/video/background_segm.hpp>

#include "node/segmentation/background_model.h"

namespace silnet::node {

// cv::BackgroundSubtractorMOG2 or KNN; shadow pixels (value 127) count as background when
// shadows are suppressed (a pixel is a shadow down to shadow_min_ratio of the background's
// brightness). Frames are first divided by a global gain estimated against the model's own
// background image (refreshed every second), as OpenCV's models do not follow lighting
// changes. Warm-up lasts the first `history / 10` frames.
class OpenCvBackgroundModel : public BackgroundModel {
 public:
  explicit OpenCvBackgroundModel(const SegmentationOptions& options);
  cv::Mat Classify(const cv::Mat& frame, bool* warming_up) override;

 private:
  SegmentationOptions options_;
  cv::Ptr<cv::BackgroundSubtractor> subtractor_;
  cv::Mat reference_;  // the model's background image
  cv::Mat last_mask_;
  long frames_ = 0;
};

// Frames are silhouettes already (CV_8UC1, or colour converted to grey): pixels above the
// threshold are foreground. Never warming up.
class MaskInputModel : public BackgroundModel {
 public:
  explicit MaskInputModel(const SegmentationOptions& options)
      : threshold_(options.mask_threshold) {}
  cv::Mat Classify(const cv::Mat& frame, bool* warming_up) override;

 private:
  int threshold_;
};

}  // namespace silnet::node
