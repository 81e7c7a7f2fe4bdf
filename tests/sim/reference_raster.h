#pragma once
// An independent silhouette rasteriser for checking the simulator's renderer: pixel rays
// from OpenCV's undistortPoints, capsules by segment-to-ray distance, ellipsoids by their
// image conic (the dual quadric projected). Slow and simple on purpose.

#include <opencv2/core/mat.hpp>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "sim/scene/primitive.h"

namespace silnet::sim::testing {

// 0/255 mask of the world-frame primitives seen by `camera`, decided at pixel centres.
cv::Mat ReferenceMask(const CameraModel& camera, const std::vector<Primitive>& world);

// Intersection over union of two 0/255 masks (1 if both are empty).
double MaskIoU(const cv::Mat& a, const cv::Mat& b);

}  // namespace silnet::sim::testing
