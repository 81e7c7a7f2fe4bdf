#pragma once
// Comparisons of hulls for the hull tests: a polyhedral hull with a voxel hull, and the same
// polyhedral hull computed on several threads.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator::hull_testing {

// How the rasterised polyhedral hull and the carved hull differ.
struct HullDifference {
  size_t differing = 0;  // voxels occupied in one grid only
  size_t far = 0;  // of those, centres farther than one voxel (diagonal) from the mesh surface
};

// Compares `raster` (RasterizeMesh(mesh, carved)) with `carved`, voxel by voxel.
HullDifference CompareWithCarvedHull(const TriangleMesh& mesh, const VoxelGrid& raster,
                                     const VoxelGrid& carved);

// Expects the exact hull of `cameras` and `masks` built on `threads` threads to succeed and to
// be exactly the one built on one (vertices, triangles, triple points, gaps filled).
void ExpectSameHullOnThreads(const std::vector<CameraModel>& cameras,
                             const std::vector<cv::Mat>& masks, int threads);

}  // namespace silnet::aggregator::hull_testing
