#pragma once
// The observations bundle adjustment works on: frontier points seen by exactly two cameras
// (thesis 3.2.1: frontier correspondences do not extend to more views), gathered from the
// view graph's links between cameras of interest.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "aggregator/calibration/view_graph.h"

namespace silnet::aggregator {

// One frontier point: cameras a < b and its raw pixels in each.
struct TwoViewTrack {
  size_t camera_a = 0;
  size_t camera_b = 0;
  Eigen::Vector2d x_a = Eigen::Vector2d::Zero();
  Eigen::Vector2d x_b = Eigen::Vector2d::Zero();
  uint64_t frame = 0;  // frame of camera a
};

// The correspondences of every link whose cameras are both `selected`, at most
// `max_per_link` per link (0 = all), taken evenly over the link's frames.
std::vector<TwoViewTrack> CollectTracks(const ViewGraph& graph, const std::vector<bool>& selected,
                                        size_t max_per_link);

}  // namespace silnet::aggregator
