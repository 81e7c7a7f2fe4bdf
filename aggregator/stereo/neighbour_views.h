#pragma once
// The k proximal views of each view for two-view matching (thesis 6.8.1): the views whose
// viewing direction at the object (from the object's centre towards the camera centre)
// makes an angle with this view's within a useful range: wide enough for depth resolution,
// narrow enough for windows to still look alike. Ranked by that angle, smallest first.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the neighbour choice.
struct NeighbourViewOptions {
  int count = 4;                // k: neighbours per view (fewer when fewer qualify)
  double min_angle_deg = 5.0;   // smaller baselines give too little depth resolution
  double max_angle_deg = 60.0;  // larger ones make the windows differ too much

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// Angle in degrees between the viewing directions of cameras `a` and `b` at `point` (world
// metres): the angle at `point` between the two camera centres.
double ViewingAngleDeg(const CameraModel& a, const CameraModel& b, const Eigen::Vector3d& point);

// For each camera the indices of its neighbours in `cameras`, at most options.count, ranked by
// viewing angle at `object_centre` (ties by index). A camera with no qualifying neighbour
// gets an empty list.
std::vector<std::vector<int>> SelectNeighbourViews(const std::vector<CameraModel>& cameras,
                                                   const Eigen::Vector3d& object_centre,
                                                   const NeighbourViewOptions& options = {});

}  // namespace silnet::aggregator
