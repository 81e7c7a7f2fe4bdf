#pragma once
// The bounding box of a mask's foreground, found by scanning only what lies outside it: the
// empty rows above and below, then each row's margins up to the box found so far, 32
// pixels at a time. On large masks with a compact subject this is a fraction of a full scan
// (cv::boundingRect reads every pixel).

#include <opencv2/core.hpp>

namespace silnet {

// The smallest rectangle holding every non-zero pixel of a CV_8UC1 mask (any stride; what
// cv::boundingRect gives for a continuous mask, and right where OpenCV 4.6's is not, on some
// views into larger images); an empty rectangle if there is none. CheckError for another type.
cv::Rect ForegroundBox(const cv::Mat& mask);

}  // namespace silnet
