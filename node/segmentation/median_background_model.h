#pragma once
// The median background model (thesis B-1.1: "a median image computed from the sequence").
// The background is the per-pixel median of a sliding window of sampled frames — when the
// subject keeps moving, the median shows the room — refreshed a band of rows per frame so
// the cost is spread evenly. Each sample remembers where it saw foreground; a pixel's median
// uses only its background observations when at least half the window has them, and all
// observations otherwise (so a ghost, or a subject that stops for long, is absorbed). Frames are
// classified against it with a learned per-pixel noise variance; a global gain, estimated robustly
// from background pixels, compensates lighting changes; darker pixels of unchanged chromaticity are
// shadows (Horprasert-style brightness/chromaticity test), not foreground.

#include <opencv2/core/mat.hpp>
#include <vector>

#include "node/segmentation/background_model.h"

namespace silnet::node {

// Sliding-window median background with gain compensation and shadow suppression.
class MedianBackgroundModel : public BackgroundModel {
 public:
  explicit MedianBackgroundModel(const SegmentationOptions& options);
  cv::Mat Classify(const cv::Mat& frame, bool* warming_up) override;

  // The current background estimate (CV_32FC3), for tests and diagnostics.
  const cv::Mat& background() const { return background_; }
  // The last estimated global gain (frame brightness / background brightness).
  double gain() const { return gain_; }

 private:
  void AddSample(const cv::Mat& frame, double gain, const cv::Mat& foreground);
  void RecomputeRows(int first, int last);
  double EstimateGain(const cv::Mat& frame) const;

  SegmentationOptions options_;
  std::vector<cv::Mat> window_;               // gain-normalised CV_8UC3 samples, a ring
  std::vector<cv::Mat> seen_background_;      // CV_8UC3 per sample: 1 where it was background
  std::vector<std::pair<int, int>> network_;  // sorting network for a full window
  std::vector<std::vector<uint8_t>> lanes_;   // per-sample values of the rows being sorted
  size_t next_slot_ = 0;
  long frames_seen_ = 0;
  cv::Mat background_;  // CV_32FC3, median of the window
  cv::Mat variance_;    // CV_32FC1, summed over channels
  cv::Mat last_mask_;   // CV_8UC1
  double gain_ = 1.0;
};

}  // namespace silnet::node
