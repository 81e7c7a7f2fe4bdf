#pragma once
// The graph cut with exact silhouette constraints, Formulation I (thesis 6.6), on the uniform
// lattice of a VoteVolume. The free cells between the visual hull and its inner offset are
// nodes twice, in a first and a second copy; the outside cells touching the hull (the surface
// layer, standing for the hull's surface) are nodes once, shared by both copies (the thesis's
// silhouette-consistency edges between a surface node and its duplicate, uncuttable). Every
// face between two cells is an n-link in each copy it belongs to, of capacity
// exp(-lambda * (v_p + v_q) / 2) as in the baseline cut (stereo_graph.h). The inner pockets
// are tied to the source in the first copy and to the sink in the second. The surface layer's
// cells where the hull's 2-coloured vertices and cone-intersection edges run
// (hull_two_colouring.h) are tied to the source (red) or the sink (blue).
//
// A cell is interior when it is on the source side in the first copy and the sink side in the
// second: the first copy's cut separates the pockets and the red parts of the hull from the
// blue ones, the second's the red parts from the pockets and the blue ones, and together they
// are one closed surface that must touch the hull between every red and blue part, i.e. on
// every true viewing edge: the rims (lemma 6.6.1).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/hull_two_colouring.h"
#include "aggregator/stereo/max_flow.h"
#include "aggregator/stereo/stereo_graph.h"
#include "aggregator/stereo/vote_volume.h"

namespace silnet::aggregator {

// The surface layer and its terminals.
struct SurfaceLayer {
  std::vector<uint8_t> in_layer;  // per cell: 1 for an outside cell 6-adjacent to a hull cell
  std::vector<int8_t> terminal;   // per cell: 1 source (red), -1 sink (blue), 0 free
  size_t cells = 0, red_cells = 0, blue_cells = 0;
  size_t clashes = 0;  // cells both colours reached, left free
};

// The surface layer of `lattice` with the colours of the hull's red and blue vertices and of
// its cone-intersection edges whose two ends have one colour (`colouring` of `hull` with its
// `provenance`), each point of them marking the layer cell nearest to it (among the cell it
// falls in and its 26 neighbours). `votes` gives the lattice's geometry.
SurfaceLayer ColourSurfaceLayer(const StereoLattice& lattice, const VoteVolume& votes,
                                const TriangleMesh& hull, const HullProvenance& provenance,
                                const HullColouring& colouring);

// The Formulation I flow graph and its sizes.
struct ExactConstraintGraph {
  MaxFlowGraph graph{0, 0};
  std::vector<int32_t> first;    // per cell: its node in the first copy (free cells), or -1
  std::vector<int32_t> second;   // per cell: its node in the second copy, or -1
  std::vector<int32_t> surface;  // per cell: its node (surface layer cells), or -1
  size_t n_links = 0;            // edges between nodes
  size_t terminal_links = 0;     // t-links (pocket faces and coloured layer cells)
};

// Builds the graph (unsolved) for `lattice` and `votes` (same lattice) with the `layer`'s
// terminals; `lambda` > 0 scales votes into costs; `ballooning` >= 0 rewards a free cell for
// being interior (5.4.1: a source t-link in the first copy, a sink t-link in the second, so
// an interior cell earns it twice, an exterior one once). Throws CheckError if the nodes exceed the
// graph's 2^31 - 1 limit.
ExactConstraintGraph BuildExactConstraintGraph(const StereoLattice& lattice,
                                               const VoteVolume& votes, const SurfaceLayer& layer,
                                               double lambda, double ballooning = 0);

// After the graph is solved: the interior cells on `votes`' lattice (pockets, and free cells on
// the source side in the first copy and the sink side in the second).
VoxelGrid ExactConstraintInterior(const StereoLattice& lattice, const VoteVolume& votes,
                                  const ExactConstraintGraph& graph);

}  // namespace silnet::aggregator
