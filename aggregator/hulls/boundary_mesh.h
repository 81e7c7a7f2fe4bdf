#pragma once
// The surface of a voxel hull as a closed, oriented, manifold triangle mesh.
//
// Every square between an occupied voxel and an empty one (or the outside of the grid: the
// grid has a closed boundary) becomes a face with its normal pointing out of the solid.
// Faces are joined across lattice edges treating occupied voxels as 6-connected: where
// two occupied voxels meet only along an edge, or only at a corner, their surfaces are kept
// apart. Vertices are made per fan of faces around a lattice corner, so a corner shared by
// separate sheets gets one vertex per sheet; an edge where two sheets touch gets a midpoint
// vertex per sheet, so no two sheets share a mesh edge. The result passes
// CheckClosedManifold, its vertices lie on the voxel lattice (a "cuberille" surface: exact,
// not smoothed), and the solid it bounds is exactly the union of occupied voxels.

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Extracts the boundary surface of the occupied voxels (empty mesh for an empty grid).
TriangleMesh ExtractBoundaryMesh(const VoxelGrid& grid);

}  // namespace silnet::aggregator
