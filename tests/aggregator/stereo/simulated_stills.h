#pragma once
// Simulated stills of the statue for the stereo tests: the views as the stereo job loads them,
// their exact polyhedral hull and the true surface.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator::testing {

// One rendered set of stills.
struct SimulatedStills {
  StereoViews views;
  TriangleMesh hull;                     // the exact visual hull of the views
  std::vector<Eigen::Vector3d> truth;    // gt_surface.ply's points
  std::vector<Eigen::Vector3d> normals;  // and unit normals
  double footprint = 0.0;                // metres per pixel at the statue
};

// Renders a ring of `cameras` at width x height (seed `seed`) into a temporary folder, loads it
// as a stills folder and removes it.
SimulatedStills MakeSimulatedStills(int cameras, int width, int height, uint64_t seed);

}  // namespace silnet::aggregator::testing
