#pragma once
// Comparison of a polyhedral hull with a voxel hull, for the hull tests.

#include <cstddef>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator::hull_testing {

// How the rasterised polyhedral hull and the carved hull differ.
struct HullDifference {
  size_t differing = 0;  // voxels occupied in one grid only
  size_t far = 0;  // of those, centres farther than one voxel (diagonal) from the mesh surface
};

// Compares `raster` (RasterizeMesh(mesh, carved)) with `carved`, voxel by voxel.
HullDifference CompareWithCarvedHull(const TriangleMesh& mesh, const VoxelGrid& raster,
                                     const VoxelGrid& carved);

}  // namespace silnet::aggregator::hull_testing
