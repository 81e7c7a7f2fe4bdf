#include "tests/aggregator/hulls/hull_comparison.h"

#include <cmath>

#include "aggregator/hulls/mesh_measure.h"

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

}  // namespace silnet::aggregator::hull_testing
