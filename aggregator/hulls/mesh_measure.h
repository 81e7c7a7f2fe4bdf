#pragma once
// Measurements of closed triangle meshes: volume, which points they contain, and distances
// between surfaces (for hull-versus-truth figures).

#include <Eigen/Core>
#include <random>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Volume enclosed by a closed, outward-oriented mesh (cubic metres).
double MeshVolume(const TriangleMesh& mesh);

// The voxels of `grid`'s geometry (origin, voxel size, dims; its occupancy is ignored) whose
// centres lie inside the closed mesh, by ray parity along z.
VoxelGrid RasterizeMesh(const TriangleMesh& mesh, const VoxelGrid& grid);

// Distance from a point to the nearest point of the mesh's triangles (brute force: for
// checks of a few points).
double PointMeshDistance(const TriangleMesh& mesh, const Eigen::Vector3d& point);

// About `count` points spread uniformly over the mesh's surface (area-weighted).
std::vector<Eigen::Vector3d> SampleMeshSurface(const TriangleMesh& mesh, size_t count,
                                               std::mt19937_64& rng);

// Directed distances between two point samplings of surfaces A and B.
struct SurfaceDistances {
  double a_to_b_max = 0, a_to_b_mean = 0;  // from each point of A to the nearest of B
  double b_to_a_max = 0, b_to_a_mean = 0;
  // The (sampled) Hausdorff distance: the larger directed maximum.
  double Hausdorff() const { return a_to_b_max > b_to_a_max ? a_to_b_max : b_to_a_max; }
};

// Nearest-neighbour distances between the samplings (exact, by k-d tree).
SurfaceDistances MeasureSurfaceDistances(const std::vector<Eigen::Vector3d>& a,
                                         const std::vector<Eigen::Vector3d>& b);

}  // namespace silnet::aggregator
