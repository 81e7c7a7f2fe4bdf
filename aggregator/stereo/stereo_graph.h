#pragma once
// The flow graph of the baseline volumetric graph cut (thesis 5.3.1, 5.4.1; Vogiatzis et al.)
// on the uniform lattice of a VoteVolume. The true surface is assumed to lie between the
// visual hull and an inner offset surface: the hull's cells are voxelised on the lattice, a
// Euclidean distance transform gives each hull cell's depth, and cells deeper than the inner
// offset (thesis 6.6: T * d_max, T = 0.4) form the inner pockets, tied to the source; cells
// outside the hull are tied to the sink. Only the cells in between ("free" cells) become graph
// nodes: an n-link of a free cell to a pocket or outside cell becomes a t-link to the source or
// the sink, so no infinite capacities are needed. Each face between two 6-neighbours is an
// n-link whose capacity is the photo-consistency cost at the face centre (thesis 6.6: "derived
// from the photo-consistency of the mid-point"), exp(-lambda * (v_p + v_q) / 2) with votes
// interpolated linearly, times the face area (1 in cell units): the cut's capacity is the
// discrete surface integral of the cost. An optional ballooning term (5.4.1) adds a source
// t-link of `ballooning` per free cell, i.e. a reward per unit of interior volume.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/max_flow.h"
#include "aggregator/stereo/vote_volume.h"

namespace silnet::aggregator {

// Squared Euclidean distance, in cells^2, from each occupied cell's centre to the nearest
// unoccupied cell centre; cells beyond the grid count as unoccupied, so the result is finite.
// 0 for unoccupied cells. Exact, in O(cells) by separable lower envelopes of parabolas
// (Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions").
std::vector<float> SquaredDistanceToOutside(const VoxelGrid& occupancy);

// Role of a lattice cell in the graph cut.
enum class CellRole : uint8_t {
  kOutside = 0,  // outside the hull: tied to the sink (exterior)
  kFree = 1,     // between the hull and the inner offset surface: a graph node
  kPocket = 2,   // deeper than the inner offset: tied to the source (interior)
};

// The hull's cells sorted by depth.
struct StereoLattice {
  std::array<int, 3> dims = {0, 0, 0};
  std::vector<CellRole> roles;    // per cell, VoxelGrid index order
  double max_depth_cells = 0;     // d_max: the deepest hull cell's distance to the outside
  double inner_offset_cells = 0;  // depth beyond which cells are pockets
  size_t hull_cells = 0, free_cells = 0, pocket_cells = 0;
};

// Classifies the cells of `hull` (occupancy on the vote lattice). A hull cell's depth is the
// distance, in cells, from its centre to the nearest non-hull cell centre (1 next to the
// outside). Pockets are hull cells deeper than the inner offset: `inner_offset_cells` if > 0,
// else `inner_offset_fraction` times the deepest cell's depth (thesis 6.6); the other hull
// cells are free.
StereoLattice ClassifyLattice(const VoxelGrid& hull, double inner_offset_fraction,
                              double inner_offset_cells);

// The closed hull mesh voxelised on `votes`' lattice: cells whose centres lie inside it.
VoxelGrid HullOnLattice(const TriangleMesh& hull, const VoteVolume& votes);

// True iff `grid` has exactly `votes`' lattice (dims, origin and cell size to 1e-9 cells).
bool SameLattice(const VoxelGrid& grid, const VoteVolume& votes);

// The flow graph over the free cells and its counts.
struct StereoGraph {
  MaxFlowGraph graph{0, 0};
  std::vector<int32_t> node_of_cell;  // graph node of each free cell, -1 for other cells
  size_t n_links = 0;                 // faces between two free cells
  size_t source_faces = 0;            // faces between a free cell and a pocket cell
  size_t sink_faces = 0;              // faces between a free cell and an outside cell
  size_t forced_faces = 0;            // faces between a pocket and an outside cell (always cut)
  double forced_cost = 0;             // their summed capacity, added to every cut
};

// Builds the graph for `lattice` with the costs of `votes` (same lattice) and returns it
// unsolved. `lambda` > 0 scales votes into costs; `ballooning` >= 0 is the reward per free
// cell kept inside. Cells beyond the grid count as outside cells with no votes. Throws
// CheckError if the free cells exceed the graph's 2^31 - 1 node limit.
StereoGraph BuildStereoGraph(const StereoLattice& lattice, const VoteVolume& votes, double lambda,
                             double ballooning);

}  // namespace silnet::aggregator
