#pragma once
// The surface of a graph cut's interior cells as a closed, oriented, manifold triangle mesh:
// the cells' boundary faces (ExtractBoundaryMesh, the exact "cuberille" surface), then
// smoothed by Taubin's lambda|mu filter ("A Signal Processing Approach to Fair Surface
// Design", SIGGRAPH 1995), which removes the lattice's staircase without shrinking the
// surface, each vertex kept within a box of +-`max_vertex_shift_cells` around its lattice
// position so the surface stays within a cell of the cut. Smoothing moves vertices only, so
// the mesh stays closed and manifold. (The cut's sub-voxel refinement and the Poisson surface
// of thesis 6.6 come later.)

#include <cstddef>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Settings of the extraction.
struct SurfaceExtractionOptions {
  int smoothing_iterations = 10;        // lambda|mu pairs; 0 = the exact cuberille surface
  double smoothing_lambda = 0.5;        // shrinking step, in (0, 1)
  double smoothing_mu = -0.53;          // inflating step, negative, |mu| > lambda
  double max_vertex_shift_cells = 0.5;  // per axis, from the vertex's lattice position

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The surface of the occupied cells of `interior`, in world coordinates (empty for an empty
// grid). The corners of the `pinned` cells (indices into `interior`) keep their lattice
// positions: the smoothing cannot pull the surface off them, so a pixel whose ray crosses a
// pinned interior cell stays covered by the surface's projection. Options must be valid
// (CheckError otherwise).
TriangleMesh ExtractCutSurface(const VoxelGrid& interior, const SurfaceExtractionOptions& options,
                               const std::vector<size_t>& pinned = {});

}  // namespace silnet::aggregator
