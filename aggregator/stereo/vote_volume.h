#pragma once
// Photo-consistency on a regular lattice of cubic cells (thesis 6.8.1): every triangulated
// two-view match adds a vote to the cell it falls in, and a cell's photo-consistency cost is
// exp(-lambda * votes), low where many matches agree on a surface. Cell (i, j, k) covers
// [origin + (i, j, k) * cell_size, origin + (i + 1, j + 1, k + 1) * cell_size) in world
// coordinates (metres), index order x fastest, then y, then z (as VoxelGrid).

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Votes per cell of a regular lattice.
struct VoteVolume {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner of cell (0, 0, 0), metres
  double cell_size = 0.0;                            // edge length, metres
  std::array<int, 3> dims = {0, 0, 0};               // cells along x, y, z
  std::vector<float> votes;                          // one per cell, >= 0

  // The lattice of cells of edge `cell_size` covering `box` (rounded up to whole cells,
  // centred on the box), no votes. Throws CheckError if the box is empty or cell_size <= 0.
  static VoteVolume Covering(const WorldBox& box, double cell_size);

  size_t size() const {
    return static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]) *
           static_cast<size_t>(dims[2]);
  }
  size_t Index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * static_cast<size_t>(dims[1]) + static_cast<size_t>(j)) *
               static_cast<size_t>(dims[0]) +
           static_cast<size_t>(i);
  }
  bool InGrid(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
  }
  // World position of the centre of cell (i, j, k).
  Eigen::Vector3d Center(int i, int j, int k) const {
    return origin + cell_size * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
  // The cell containing world point `p`, or nullopt outside the lattice.
  std::optional<std::array<int, 3>> CellOf(const Eigen::Vector3d& p) const;
  // Photo-consistency cost of cell `index`: exp(-lambda * votes), in (0, 1].
  double Cost(size_t index, double lambda) const;
};

}  // namespace silnet::aggregator
