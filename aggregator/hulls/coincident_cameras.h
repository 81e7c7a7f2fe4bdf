#pragma once
// Cameras that stand at one viewpoint. The exact hull needs distinct camera centres: two
// cameras at one centre give cone faces through each other's apex (or the very same faces),
// which no sweep decides consistently. A rig that repeats a view (the Middlebury temple ring's
// first and eleventh photographs share one camera) has such a pair.

#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Which cameras repeat another.
struct CoincidentCameras {
  // Per camera: the first camera with the same projection (image size, intrinsics, pose and
  // lens within 1e-9 relative), or itself.
  std::vector<int> same_as;
  // Two cameras at one centre (within 1e-9 of the rig's size) that do not share a projection,
  // named; empty if there are none.
  std::string conflict;
};

// Finds the cameras that repeat another and those that share a centre only.
CoincidentCameras FindCoincidentCameras(const std::vector<CameraModel>& cameras);

}  // namespace silnet::aggregator
