#include "aggregator/hulls/voxel_grid.h"

#include <algorithm>
#include <cmath>

#include "shared/util/check.h"

namespace silnet::aggregator {

VoxelGrid VoxelGrid::Empty(const Eigen::Vector3d& origin, double voxel_size,
                           const std::array<int, 3>& dims) {
  SILNET_CHECK(dims[0] >= 0 && dims[1] >= 0 && dims[2] >= 0);
  VoxelGrid grid;
  grid.origin = origin;
  grid.voxel_size = voxel_size;
  grid.dims = dims;
  grid.occupied.assign(grid.size(), 0);
  return grid;
}

size_t VoxelGrid::CountOccupied() const {
  return static_cast<size_t>(
      std::count_if(occupied.begin(), occupied.end(), [](uint8_t v) { return v != 0; }));
}

WorldBox VoxelGrid::Bounds() const {
  return WorldBox(origin, Corner(dims[0], dims[1], dims[2]));
}

VoxelGrid GridCovering(const WorldBox& box, double voxel_size) {
  SILNET_CHECK(voxel_size > 0.0);
  SILNET_CHECK_MSG(!box.isEmpty(), "cannot build a voxel grid over an empty box");
  std::array<int, 3> dims{};
  Eigen::Vector3d origin;
  for (int a = 0; a < 3; ++a) {
    const double extent = box.max()[a] - box.min()[a];
    dims[static_cast<size_t>(a)] = std::max(1, static_cast<int>(std::ceil(extent / voxel_size)));
    const double covered = dims[static_cast<size_t>(a)] * voxel_size;
    origin[a] = box.min()[a] - 0.5 * (covered - extent);
  }
  return VoxelGrid::Empty(origin, voxel_size, dims);
}

}  // namespace silnet::aggregator
