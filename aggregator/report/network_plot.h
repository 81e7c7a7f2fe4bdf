#pragma once
// The camera network in 3D as two orthographic views, from above and from the side: each
// placed camera as a small viewing pyramid (frustum) labelled with its id, and the inlier
// frontier points as a light point cloud (at most 20000 of them, evenly subsampled).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// A right-handed orthonormal frame for looking at a reconstruction whose world frame is an
// arbitrary similarity: `up` and two horizontal axes, `horizontal` along the largest spread
// of the camera centres and `across` = up x horizontal.
struct ViewFrame {
  Eigen::Vector3d horizontal = Eigen::Vector3d::UnitX();
  Eigen::Vector3d across = Eigen::Vector3d::UnitY();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

// The frame of the placed cameras. "Up" is the normal of the best-fit plane of the camera
// centres when they span a plane (rings, domes and arcs are set up level) and that normal
// agrees within 60 degrees with the cameras' mean image-up direction (-y axis, since
// cameras are mounted roughly upright); otherwise the mean image-up direction itself. The
// sign always follows the mean image-up. Without placed cameras: the world axes.
ViewFrame NetworkViewFrame(const NetworkCalibration& calibration);

// The two views side by side in one BGR image of width x height pixels.
cv::Mat DrawCameraNetwork(const NetworkCalibration& calibration, int width = 1400,
                          int height = 700);

}  // namespace silnet::aggregator
