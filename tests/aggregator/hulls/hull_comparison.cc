#include "tests/aggregator/hulls/hull_comparison.h"

#include <gtest/gtest.h>

#include <cmath>

#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/polyhedral_hull.h"

namespace silnet::aggregator::hull_testing {

HullDifference CompareWithCarvedHull(const TriangleMesh& mesh, const VoxelGrid& raster,
                                     const VoxelGrid& carved) {
  HullDifference difference;
  for (int k = 0; k < raster.dims[2]; ++k) {
    for (int j = 0; j < raster.dims[1]; ++j) {
      for (int i = 0; i < raster.dims[0]; ++i) {
        if (raster.IsOccupied(i, j, k) == carved.IsOccupied(i, j, k)) continue;
        ++difference.differing;
        // A change of state among the raster's neighbours puts the surface within one
        // voxel; otherwise measure the distance exactly.
        bool in = false, out = false;
        for (int dz = -1; dz <= 1; ++dz) {
          for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx)
              (raster.IsOccupied(i + dx, j + dy, k + dz) ? in : out) = true;
          }
        }
        if (in && out) continue;
        if (PointMeshDistance(mesh, raster.Center(i, j, k)) > std::sqrt(3.0) * raster.voxel_size)
          ++difference.far;
      }
    }
  }
  return difference;
}

void ExpectSameHullOnThreads(const std::vector<CameraModel>& cameras,
                             const std::vector<cv::Mat>& masks, int threads) {
  PolyhedralHullOptions one, several;
  one.threads = 1;
  several.threads = threads;
  const PolyhedralHullResult a = ComputePolyhedralHull(cameras, masks, one);
  const PolyhedralHullResult b = ComputePolyhedralHull(cameras, masks, several);
  ASSERT_TRUE(a.success) << a.reason;
  ASSERT_TRUE(b.success) << b.reason;
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.stats.triple_points, b.stats.triple_points);
  EXPECT_EQ(a.stats.gaps_filled, b.stats.gaps_filled);
}

}  // namespace silnet::aggregator::hull_testing
