#pragma once
// The second pass of shadow suppression (thesis B-1.1), shared by the video background model
// and the single-image background difference: a shadow keeps the background's texture, so
// the brightness ratio of image to background is locally constant over it, while on an object
// it follows the object's own texture.

#include <opencv2/core/mat.hpp>

namespace silnet::node {

// Decides the shadow candidates of `mask` (CV_8UC1; 128 marks a candidate): a candidate whose
// brightness ratios `ratio` (CV_32FC1, the mask's size, 0 outside candidates) vary over the
// candidates of its 5x5 window with a standard deviation below `texture` becomes background
// (0), any other foreground (255). Other mask values are left alone.
void ResolveShadowCandidates(cv::Mat mask, const cv::Mat& ratio, double texture);

}  // namespace silnet::node
