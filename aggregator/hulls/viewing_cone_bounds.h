#pragma once
// The box a visual hull can occupy, from the silhouettes alone: each camera's silhouette
// bounding rectangle back-projected is a four-sided viewing cone (in front of the camera);
// the bounding box of the intersection of all cones bounds the hull (thesis 4.2). A side of
// the rectangle that touches the image border is dropped, because the subject may continue
// outside that image. Distorted cameras use the rectangle's undistorted outline.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The bounding box of the viewing-cone intersection, or why there is none.
struct ViewingConeBounds {
  bool success = false;
  WorldBox box;        // valid when success
  std::string reason;  // why not, when !success ("silhouette of cam03 is empty", "unbounded")
};

// Why `mask` cannot be `camera`'s silhouette mask (it is not a CV_8UC1 image of the
// camera's size), or empty if it can.
std::string MaskShapeProblem(const CameraModel& camera, const cv::Mat& mask);

// Computes the box from one CV_8UC1 mask per camera (non-zero = silhouette). Fails (as
// data) when a mask is empty or of the wrong size, or when the cones do not bound a finite
// region (e.g. all cameras look the same way).
ViewingConeBounds ComputeViewingConeBounds(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Mat>& masks);

// The same from each camera's silhouette bounding rectangle (pixels, covering every
// silhouette pixel; empty when the silhouette is).
ViewingConeBounds ComputeViewingConeBounds(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Rect>& rects);

}  // namespace silnet::aggregator
