#pragma once
// Where a silhouette has T-junctions (thesis 6.2-6.3): the outline of one part of the subject
// ends against the outline of another part in front of or behind it, and the outline turns
// sharply inward there. The visual hull builds its sheets and spikes from the viewing rays
// through such corners, and stereo built on the hull inherits them; issue 17 asks for the
// accuracy there separately. A corner is found on the outline (findContours, holes included)
// where the chord between the points `arm_px` before and after subtends less than
// `max_angle_deg` and its midpoint lies outside the silhouette (an inward turn). The T-junction
// region of the true surface is its points that project within `radius_px` of such a corner
// in some view and lie near that view's rim (the viewing ray within `max_rim_cosine` of
// tangent): the surface that forms those corners.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the corner detection and the region.
struct TJunctionOptions {
  int arm_px = 4;                // outline steps to the chord's ends, >= 2
  double max_angle_deg = 120;    // sharper than this is a corner, (0, 180)
  double radius_px = 3;          // a true point projecting this close to a corner, > 0
  double max_rim_cosine = 0.35;  // |cos| of the angle between normal and ray, in (0, 1]

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The inward corners of the outline of `mask` (CV_8UC1, non-zero = silhouette), pixel
// coordinates, one per corner (the sharpest outline point of each run of corner points).
std::vector<cv::Point> InwardOutlineCorners(const cv::Mat& mask, const TJunctionOptions& options);

// One flag per true point (`points` with unit outward `normals`): 1 if it lies in the
// T-junction region of any of the views (`cameras` with their `masks`). CheckError for
// mismatched sizes or invalid options.
std::vector<uint8_t> TJunctionRegion(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals,
                                     const std::vector<CameraModel>& cameras,
                                     const std::vector<cv::Mat>& masks,
                                     const TJunctionOptions& options = {});

}  // namespace silnet::aggregator
