#pragma once
// Suzuki-Abe border following of a mask's foreground inside a box, with the same rings and
// two-level hierarchy as OpenCV's cv::findContours in RETR_CCOMP / CHAIN_APPROX_NONE mode
// (same start pixels, directions, point order and ring order), faster on silhouettes: the mask
// is copied and thresholded in one pass, the raster scan skips runs 16 pixels at a time, and
// the border follower picks its next pixel from the eight neighbours' bits instead of testing
// them one by one. Contour extraction keeps bit for bit the outlines it had with OpenCV's
// tracer; figures in docs/PERFORMANCE.md.

#include <opencv2/core.hpp>
#include <vector>

namespace silnet {

// The borders of the non-zero pixels of `mask(box)` (CV_8UC1, `box` inside the mask), in
// mask coordinates: exactly what cv::findContours(mask(box), rings, hierarchy, cv::RETR_CCOMP,
// cv::CHAIN_APPROX_NONE, box.tl()) returns (OpenCV 4.x), including on masks with more
// borders than its labels tell apart (there it hands the box to OpenCV). Empty for an empty
// box. CheckError for another type or a box outside the mask.
void TraceBorders(const cv::Mat& mask, const cv::Rect& box,
                  std::vector<std::vector<cv::Point>>& rings, std::vector<cv::Vec4i>& hierarchy);

}  // namespace silnet
