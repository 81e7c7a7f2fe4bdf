#pragma once
// Per-pixel background models: each turns a frame into a raw foreground mask (before
// clean-up). See SilhouetteSegmenter for the whole segmentation of a frame.

#include <memory>
#include <opencv2/core/mat.hpp>

#include "node/segmentation/segmentation_options.h"

namespace silnet::node {

// A background model that learns from the frames it classifies.
class BackgroundModel {
 public:
  virtual ~BackgroundModel() = default;
  // Raw foreground (CV_8UC1, 0/255) of `frame`, learning from it. Sets `*warming_up` while the
  // model has not seen enough frames to be trusted.
  virtual cv::Mat Classify(const cv::Mat& frame, bool* warming_up) = 0;
};

// The model for `options.method`. Throws InputError for invalid options.
std::unique_ptr<BackgroundModel> MakeBackgroundModel(const SegmentationOptions& options);

}  // namespace silnet::node
