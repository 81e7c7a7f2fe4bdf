#include "node/segmentation/opencv_background_model.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "node/segmentation/median_background_model.h"
#include "shared/util/check.h"

namespace silnet::node {

OpenCvBackgroundModel::OpenCvBackgroundModel(const SegmentationOptions& options)
    : options_(options) {
  if (options.method == SegmentationMethod::kMog2) {
    auto mog2 = cv::createBackgroundSubtractorMOG2(options.history, options.opencv_threshold, true);
    mog2->setShadowThreshold(options.shadow_min_ratio);
    subtractor_ = mog2;
  } else {
    auto knn = cv::createBackgroundSubtractorKNN(
        options.history, options.opencv_threshold * options.opencv_threshold, true);
    knn->setShadowThreshold(options.shadow_min_ratio);
    subtractor_ = knn;
  }
}

cv::Mat OpenCvBackgroundModel::Classify(const cv::Mat& frame, bool* warming_up) {
  // Global gain against the background image, over a sparse grid of background pixels.
  cv::Mat input = frame;
  if (!reference_.empty() && reference_.size() == frame.size()) {
    double frame_sum = 0.0, reference_sum = 0.0;
    for (int y = 2; y < frame.rows; y += 8) {
      const auto* in = frame.ptr<uint8_t>(y);
      const auto* ref = reference_.ptr<uint8_t>(y);
      const auto* mask = last_mask_.ptr<uint8_t>(y);
      for (int x = 3; x < frame.cols; x += 8) {
        if (mask[x] != 0) continue;
        frame_sum += in[3 * x] + in[3 * x + 1] + in[3 * x + 2];
        reference_sum += ref[3 * x] + ref[3 * x + 1] + ref[3 * x + 2];
      }
    }
    if (frame_sum > 0.0 && reference_sum > 0.0) {
      frame.convertTo(input, CV_8UC3, std::clamp(reference_sum / frame_sum, 0.5, 2.0));
    }
  }
  cv::Mat raw;
  subtractor_->apply(input, raw);
  if (frames_ % 30 == 0) subtractor_->getBackgroundImage(reference_);
  *warming_up = ++frames_ < std::max(2, options_.history / 10);
  // 255 foreground, 127 shadow, 0 background.
  last_mask_ = options_.suppress_shadows ? cv::Mat(raw > 200) : cv::Mat(raw > 0);
  return last_mask_;
}

cv::Mat MaskInputModel::Classify(const cv::Mat& frame, bool* warming_up) {
  *warming_up = false;
  cv::Mat grey = frame;
  if (frame.channels() == 3) cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  SILNET_CHECK_MSG(grey.type() == CV_8UC1, "mask input must be 8-bit");
  return grey > threshold_;
}

std::unique_ptr<BackgroundModel> MakeBackgroundModel(const SegmentationOptions& options) {
  if (const std::string reason = options.Validate(); !reason.empty()) throw InputError(reason);
  switch (options.method) {
    case SegmentationMethod::kMedian:
      return std::make_unique<MedianBackgroundModel>(options);
    case SegmentationMethod::kMog2:
    case SegmentationMethod::kKnn:
      return std::make_unique<OpenCvBackgroundModel>(options);
    case SegmentationMethod::kMaskInput:
      return std::make_unique<MaskInputModel>(options);
  }
  throw InputError("unsupported segmentation method");
}

}  // namespace silnet::node
