#include "aggregator/hulls/silhouette_interpolation.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// True if the mask has both silhouette and background pixels.
bool HasOutline(const cv::Mat& mask) {
  const int inside = cv::countNonZero(mask);
  return inside > 0 && inside < static_cast<int>(mask.total());
}

cv::Mat Binarised(const cv::Mat& mask) {
  return (mask != 0);
}

}  // namespace

cv::Mat SignedDistanceMap(const cv::Mat& mask) {
  SILNET_CHECK(mask.type() == CV_8UC1);
  SILNET_CHECK_MSG(HasOutline(mask), "a signed distance map needs silhouette and background");
  const cv::Mat inside = Binarised(mask);
  const cv::Mat outside = (mask == 0);
  cv::Mat to_background, to_silhouette;
  // Distance of each non-zero pixel to the nearest zero pixel (pixel centre to centre).
  cv::distanceTransform(inside, to_background, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(outside, to_silhouette, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat signed_distance(mask.size(), CV_32FC1);
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* in = inside.ptr<uint8_t>(y);
    const float* d_in = to_background.ptr<float>(y);
    const float* d_out = to_silhouette.ptr<float>(y);
    float* out = signed_distance.ptr<float>(y);
    for (int x = 0; x < mask.cols; ++x)
      out[x] = in[x] ? d_in[x] - 0.5f : 0.5f - d_out[x];
  }
  return signed_distance;
}

cv::Mat InterpolateSilhouette(const cv::Mat& mask_k, const cv::Mat& mask_k1, double fraction) {
  SILNET_CHECK(mask_k.type() == CV_8UC1 && mask_k1.type() == CV_8UC1);
  SILNET_CHECK(mask_k.size() == mask_k1.size());
  SILNET_CHECK(fraction >= 0.0 && fraction <= 1.0);
  if (fraction == 0.0) return Binarised(mask_k);
  if (fraction == 1.0) return Binarised(mask_k1);
  if (!HasOutline(mask_k) || !HasOutline(mask_k1)) {
    return Binarised(fraction < 0.5 ? mask_k : mask_k1);
  }
  // Outside both silhouettes both distances are negative, so only the box around them
  // (with a background margin, so inside distances still find the background) is computed.
  constexpr int kMargin = 2;
  cv::Rect roi = cv::boundingRect(mask_k) | cv::boundingRect(mask_k1);
  roi = cv::Rect(roi.x - kMargin, roi.y - kMargin, roi.width + 2 * kMargin,
                 roi.height + 2 * kMargin) &
        cv::Rect(0, 0, mask_k.cols, mask_k.rows);
  if (!HasOutline(mask_k(roi)) || !HasOutline(mask_k1(roi)))
    roi = cv::Rect(0, 0, mask_k.cols, mask_k.rows);
  cv::Mat blend;
  cv::addWeighted(SignedDistanceMap(mask_k(roi)), 1.0 - fraction, SignedDistanceMap(mask_k1(roi)),
                  fraction, 0.0, blend);
  cv::Mat result = cv::Mat::zeros(mask_k.size(), CV_8UC1);
  result(roi).setTo(255, blend > 0.0f);
  return result;
}

}  // namespace silnet::aggregator
