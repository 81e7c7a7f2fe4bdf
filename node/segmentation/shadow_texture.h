#pragma once
// Shadow suppression (thesis B-1.1), shared by the video background model, the single-image
// background difference and its weak evidence: a pixel is a shadow candidate when it is darker
// than the background with the background's chromaticity (first pass), and a shadow when its
// texture is the background's, so the brightness ratio of image to background is locally
// constant over it, while on an object it follows the object's own texture (second pass).

#include <opencv2/core/mat.hpp>

#include "node/segmentation/segmentation_options.h"

namespace silnet::node {

// The first pass: the brightness ratio of the BGR pixel `image` to its `background` when the
// pixel looks like a shadow on it (darker by a ratio in [shadow_min_ratio, shadow_max_ratio],
// chromatic distortion below shadow_chroma); 0 when it does not.
template <class T>
T ShadowRatio(const T image[3], const T background[3], const SegmentationOptions& options) {
  const T bb =
      background[0] * background[0] + background[1] * background[1] + background[2] * background[2];
  const T alpha =
      bb > T(1)
          ? (image[0] * background[0] + image[1] * background[1] + image[2] * background[2]) / bb
          : T(1);
  // The bounds compared in double, as the options hold them.
  if (!(static_cast<double>(alpha) >= options.shadow_min_ratio &&
        static_cast<double>(alpha) <= options.shadow_max_ratio))
    return T(0);
  T distortion = 0;
  for (int c = 0; c < 3; ++c) {
    const T d = image[c] - alpha * background[c];
    distortion += d * d;
  }
  const T chroma2 = static_cast<T>(options.shadow_chroma * options.shadow_chroma);
  return distortion < chroma2 * alpha * alpha * bb ? alpha : T(0);
}

// Decides the shadow candidates of `mask` (CV_8UC1; 128 marks a candidate): a candidate whose
// brightness ratios `ratio` (CV_32FC1, the mask's size, 0 outside candidates) vary over the
// candidates of its 5x5 window with a standard deviation below `texture` becomes background
// (0), any other foreground (255). Other mask values are left alone.
void ResolveShadowCandidates(cv::Mat mask, const cv::Mat& ratio, double texture);

}  // namespace silnet::node
