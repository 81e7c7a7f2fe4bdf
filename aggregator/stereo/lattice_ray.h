#pragma once
// Walking a viewing ray through a voxel lattice: the cells it passes, sampled at half a cell.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>

#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Where the ray centre + t * direction (t >= 0) is inside `box`: [t_in, t_out], if anywhere.
std::optional<std::pair<double, double>> ClipRay(const WorldBox& box, const Eigen::Vector3d& centre,
                                                 const Eigen::Vector3d& direction);

// Calls `visit(t, cell)` for the points centre + t * direction (t >= 0, `direction` of unit
// length) every half cell of `grid` inside its box, in increasing t, with the index of the
// cell holding each (a cell is visited once or more per pass). Nothing is visited when the ray
// misses the box.
template <typename Visit>
void WalkRay(const VoxelGrid& grid, const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
             Visit&& visit) {
  const auto range = ClipRay(grid.Bounds(), centre, direction);
  if (!range) return;
  const double step = 0.5 * grid.voxel_size;
  for (double t = range->first + 0.5 * step; t < range->second; t += step) {
    const Eigen::Vector3d cell = (centre + t * direction - grid.origin) / grid.voxel_size;
    const int i = static_cast<int>(std::floor(cell.x()));
    const int j = static_cast<int>(std::floor(cell.y()));
    const int k = static_cast<int>(std::floor(cell.z()));
    if (grid.InGrid(i, j, k)) visit(t, grid.Index(i, j, k));
  }
}

}  // namespace silnet::aggregator
