#pragma once
// A regular grid of cubic voxels with one occupancy byte per voxel: the volumetric visual
// hull (thesis 4.2) is stored in it. Voxel (i, j, k) covers
// [origin + (i, j, k) * voxel_size, origin + (i + 1, j + 1, k + 1) * voxel_size) in world
// coordinates (metres) and its centre is origin + (i + 1/2, j + 1/2, k + 1/2) * voxel_size.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace silnet::aggregator {

// An axis-aligned box in world coordinates, metres.
using WorldBox = Eigen::AlignedBox3d;

// Voxel occupancy on a regular grid; index order x fastest, then y, then z.
struct VoxelGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner of voxel (0, 0, 0), metres
  double voxel_size = 0.0;                           // edge length, metres
  std::array<int, 3> dims = {0, 0, 0};               // voxels along x, y, z
  std::vector<uint8_t> occupied;                     // 1 = inside the hull, 0 = carved

  // An empty (all carved) grid of `dims` voxels; `dims` must be non-negative.
  static VoxelGrid Empty(const Eigen::Vector3d& origin, double voxel_size,
                         const std::array<int, 3>& dims);

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
  // Occupancy of voxel (i, j, k); false outside the grid (the grid has a closed boundary).
  bool IsOccupied(int i, int j, int k) const {
    return InGrid(i, j, k) && occupied[Index(i, j, k)] != 0;
  }
  // World position of a lattice corner (i, j, k) (voxel corners, not centres).
  Eigen::Vector3d Corner(double i, double j, double k) const {
    return origin + voxel_size * Eigen::Vector3d(i, j, k);
  }
  // World position of the centre of voxel (i, j, k).
  Eigen::Vector3d Center(int i, int j, int k) const { return Corner(i + 0.5, j + 0.5, k + 0.5); }
  // World position of the centre of the voxel with Index `index`.
  Eigen::Vector3d CenterOf(size_t index) const {
    const auto nx = static_cast<size_t>(dims[0]), ny = static_cast<size_t>(dims[1]);
    return Center(static_cast<int>(index % nx), static_cast<int>(index / nx % ny),
                  static_cast<int>(index / nx / ny));
  }
  // Number of occupied voxels.
  size_t CountOccupied() const;
  // The world box the grid covers.
  WorldBox Bounds() const;
};

// The grid of voxels of edge `voxel_size` that covers `box` (rounded up to whole voxels,
// centred on the box), all carved. Throws CheckError if the box is empty or voxel_size <= 0.
VoxelGrid GridCovering(const WorldBox& box, double voxel_size);

}  // namespace silnet::aggregator
