#pragma once
// Volumetric visual hull by voxel carving (thesis 4.2): a voxel is kept iff its centre
// projects into the silhouette of every camera that sees it. A camera does not see (and so
// never carves) a centre behind it or one whose pixel lies outside its image: the subject
// may leave one camera's field of view while the others still constrain it, and carving by
// "outside the image" would cut it off. The pixel of a projection (u, v) is
// (floor(u + 0.5), floor(v + 0.5)) (integer pixels are pixel centres).
//
// Carving runs coarse to fine over an octree: a cell whose projected bounding rectangle is
// entirely silhouette (or entirely off-image) in a camera needs no more tests against that
// camera, a cell entirely background in one camera is carved whole, and only the remaining
// boundary cells are split into eight. For undistorted cameras the projected rectangle
// bounds every voxel centre's projection exactly, so the result equals the voxel-by-voxel
// test; for distorted cameras the rectangle is widened by `distortion_margin_px`.

#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the carving.
struct VoxelHullOptions {
  double voxel_size = 0.01;          // voxel edge, metres
  std::optional<WorldBox> bounds;    // region to carve; unset = viewing-cone bounds
  double bounds_padding_voxels = 1;  // derived bounds are grown by this many voxels per side
  int octree_levels = 5;             // top cells are 2^levels voxels on a side
  int threads = 0;                   // 0 = all cores, 1 = the calling thread only
  double distortion_margin_px = 2;   // widening of projected cells for distorted cameras

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// Counts describing how much work the carving did.
struct VoxelHullStats {
  size_t cells_visited = 0;  // octree cells classified, all levels
  size_t voxels_tested = 0;  // single voxels tested point-wise
};

// The carved hull, or why there is none.
struct VoxelHullResult {
  bool success = false;
  std::string reason;  // when !success
  VoxelGrid grid;      // occupancy; grid.Bounds() covers the carved region
  VoxelHullStats stats;
};

// Carves the hull of one frame: `masks[c]` (CV_8UC1, non-zero = silhouette, camera c's
// size) is camera c's silhouette. At most 64 cameras. Bad inputs and empty silhouettes
// are reported in the result, not thrown.
VoxelHullResult CarveVoxelHull(const std::vector<CameraModel>& cameras,
                               const std::vector<cv::Mat>& masks, const VoxelHullOptions& options);

// The occupancy of one voxel centre by the rule above, tested against every camera
// directly (slow; the reference the octree must agree with).
bool VoxelCentreInHull(const std::vector<CameraModel>& cameras, const std::vector<cv::Mat>& masks,
                       const Eigen::Vector3d& centre);

}  // namespace silnet::aggregator
