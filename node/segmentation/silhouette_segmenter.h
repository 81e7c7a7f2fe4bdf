#pragma once
// Segmentation of one camera's frames into silhouettes: a background model, clean-up and
// optional graph-cut refinement (thesis appendix B-1).

#include <memory>
#include <opencv2/core/mat.hpp>

#include "node/segmentation/background_model.h"
#include "node/segmentation/mask_cleanup.h"

namespace silnet::node {

// One frame's silhouette.
struct Segmentation {
  cv::Mat mask;             // CV_8UC1, 0 background, 255 foreground
  bool warming_up = false;  // the model is still learning: the mask is unreliable
  CleanupStats cleanup;
};

// Segments the frames of one camera, in order.
class SilhouetteSegmenter {
 public:
  // Throws InputError for invalid options.
  explicit SilhouetteSegmenter(const SegmentationOptions& options);

  // The silhouette of `frame` (CV_8UC3 BGR; CV_8UC1 or BGR for mask input). Throws
  // InputError if the frame size differs from earlier frames or the type is unsupported.
  Segmentation Segment(const cv::Mat& frame);
  const SegmentationOptions& options() const { return options_; }

 private:
  SegmentationOptions options_;
  SegmentationOptions cleanup_;  // options_ as clean-up applies them
  std::unique_ptr<BackgroundModel> model_;
  cv::Size size_;
};

}  // namespace silnet::node
