#pragma once
// Sub-frame silhouettes (thesis 4.2.1): the silhouette of a camera between two of its
// frames, from the linear blend of the two frames' signed distance maps, thresholded at 0.
// A moving outline slides between its two positions instead of the union or intersection
// a pixel-wise blend would give.

#include <opencv2/core/mat.hpp>

namespace silnet::aggregator {

// CV_32FC1 signed Euclidean distance to the silhouette outline, in pixels: positive inside
// (non-zero pixels), negative outside, with the zero level half a pixel outside the
// outermost silhouette pixels (so a silhouette pixel is >= 0.5, a background pixel <= -0.5).
// `mask` is CV_8UC1 and must contain both silhouette and background pixels.
cv::Mat SignedDistanceMap(const cv::Mat& mask);

// The silhouette at fraction `fraction` in [0, 1] from `mask_k` (frame k) to `mask_k1`
// (frame k + 1): CV_8UC1, 255 where (1 - f) * sd_k + f * sd_k1 > 0, else 0. Returns the
// first mask (as 0/255) at f = 0 and the second at f = 1. If either mask has no silhouette
// or no background pixel the nearer frame's mask is returned. Throws CheckError for
// masks of different sizes or types other than CV_8UC1.
cv::Mat InterpolateSilhouette(const cv::Mat& mask_k, const cv::Mat& mask_k1, double fraction);

}  // namespace silnet::aggregator
