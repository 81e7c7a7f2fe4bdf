#include "node/segmentation/shadow_texture.h"

#include <opencv2/imgproc.hpp>

namespace silnet::node {

void ResolveShadowCandidates(cv::Mat mask, const cv::Mat& ratio, double texture) {
  // Statistics over the candidates of each window only, so that windows across a shadow's
  // edge are judged by the shadow pixels alone.
  const cv::Mat candidates = mask == 128;
  cv::Mat weight, weighted_sum, weighted_square;
  candidates.convertTo(weight, CV_32F, 1.0 / 255.0);
  cv::boxFilter(weight, weight, CV_32F, cv::Size(5, 5), cv::Point(-1, -1), false);
  cv::boxFilter(ratio, weighted_sum, CV_32F, cv::Size(5, 5), cv::Point(-1, -1), false);
  cv::boxFilter(ratio.mul(ratio), weighted_square, CV_32F, cv::Size(5, 5), cv::Point(-1, -1),
                false);
  const float texture2 = static_cast<float>(texture * texture);
  for (int y = 0; y < mask.rows; ++y) {
    uint8_t* out = mask.ptr<uint8_t>(y);
    const float* w = weight.ptr<float>(y);
    const float* s1 = weighted_sum.ptr<float>(y);
    const float* s2 = weighted_square.ptr<float>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (out[x] != 128) continue;
      const float mean = s1[x] / w[x];
      out[x] = s2[x] / w[x] - mean * mean < texture2 ? 0 : 255;
    }
  }
}

}  // namespace silnet::node
