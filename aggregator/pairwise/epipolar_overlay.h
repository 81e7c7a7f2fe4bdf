#pragma once
// Pictures of an estimated pair: both views side by side at one frame, with the silhouette
// hulls (over the frame's image when there is one), the outer epipolar tangents from each
// epipole, the frontier points they touch, every inlier frontier point of the sequence,
// and the epipolar lines in view j of a few points of view i.

#include <opencv2/core/mat.hpp>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"

namespace silnet::aggregator {

// The overlay of frame `frame_i` of camera i (and the simultaneous frame of camera j).
// `image_i` / `image_j` (any type, may be empty) are drawn underneath.
cv::Mat DrawPairOverlay(const PairwiseResult& pair, const SilhouetteSequence& i,
                        const SilhouetteSequence& j, uint64_t frame_i, const cv::Mat& image_i = {},
                        const cv::Mat& image_j = {});

// A frame of camera i with valid frontier points in both views near the middle of the
// sequence, or the first usable frame.
uint64_t OverlayFrame(const PairwiseResult& pair, const SilhouetteSequence& i,
                      const SilhouetteSequence& j);

}  // namespace silnet::aggregator
