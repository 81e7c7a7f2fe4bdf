#pragma once
// Douglas-Peucker simplification of a closed ring, point for point what cv::approxPolyDP
// gives for closed float curves (OpenCV 4.x: three passes for a far pair of points, the split
// recursion in its order, its final pass over nearly straight corners, the same double
// arithmetic on float differences), with the distance scans two points at a time. Contour
// extraction keeps bit for bit the outlines it had with OpenCV's; figures in
// docs/PERFORMANCE.md.

#include <opencv2/core.hpp>
#include <vector>

namespace silnet {

// The points cv::approxPolyDP(ring, out, tolerance, true) keeps, in its order. CheckError
// where OpenCV fails (a split between two equal points) or for a negative tolerance.
std::vector<cv::Point2f> SimplifyClosedRing(const std::vector<cv::Point2f>& ring, double tolerance);

}  // namespace silnet
