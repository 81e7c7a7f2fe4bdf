#include "node/segmentation/silhouette_segmenter.h"

#include "shared/util/check.h"

namespace silnet::node {

SilhouetteSegmenter::SilhouetteSegmenter(const SegmentationOptions& options)
    : options_(options), cleanup_(options), model_(MakeBackgroundModel(options)) {
  // Precomputed silhouettes keep their shape: no morphology, only specks and pinholes.
  if (options.method == SegmentationMethod::kMaskInput) {
    cleanup_.open_radius = 0;
    cleanup_.close_radius = 0;
  }
}

Segmentation SilhouetteSegmenter::Segment(const cv::Mat& frame) {
  if (frame.empty()) throw InputError("empty frame");
  if (size_.area() == 0) size_ = frame.size();
  if (frame.size() != size_) {
    throw InputError("frame is " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                     ", the camera's frames are " + std::to_string(size_.width) + "x" +
                     std::to_string(size_.height));
  }
  const bool mask_input = options_.method == SegmentationMethod::kMaskInput;
  if (frame.depth() != CV_8U || (frame.channels() != 3 && !(mask_input && frame.channels() == 1))) {
    throw InputError(mask_input ? "mask input frames must be 8-bit grey or BGR"
                                : "colour segmentation needs 8-bit BGR frames");
  }
  Segmentation result;
  result.mask = model_->Classify(frame, &result.warming_up);
  result.cleanup = CleanMask(&result.mask, cleanup_);
  if (options_.graph_cut && !mask_input && !result.warming_up) {
    RefineWithGraphCut(frame, &result.mask, options_.graph_cut_band);
    result.cleanup = CleanMask(&result.mask, cleanup_);
  }
  return result;
}

}  // namespace silnet::node
