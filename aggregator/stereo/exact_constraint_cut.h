#pragma once
// The graph cut with exact silhouette constraints (thesis 6.4-6.6, Formulation I) as a stage of
// the uniform stereo: the exact hull's vertices 2-coloured (hull_two_colouring.h, the rim
// graph's photo-consistency from the votes), the lattice's surface layer coloured and the
// doubled graph cut (exact_constraint_graph.h), the interior's surface extracted. The
// alternative to the baseline cut's silhouette steps (volumetric_graph_cut.h), selected by
// `silnet-aggregator stereo --silhouette-constraints exact`.

#include <cstddef>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/hull_two_colouring.h"
#include "aggregator/stereo/volumetric_graph_cut.h"
#include "aggregator/stereo/vote_volume.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// What the constraints' construction found.
struct ExactConstraintStats {
  HullColouringStats colouring;
  size_t layer_cells = 0, red_cells = 0, blue_cells = 0, clashes = 0;  // SurfaceLayer
  // Free cells on the sink side in the first copy and the source side in the second (a double
  // cover no surface explains; 0 in a regular cut).
  size_t twisted_cells = 0;
  double seconds_colouring = 0;
};

// The cut and its figures.
struct ExactConstraintCutResult {
  VolumetricGraphCutResult cut;  // interior, surface and the graph's sizes and times
  ExactConstraintStats exact;
};

// Runs the stage on `votes` inside `hull_cells` (the hull on the votes' lattice, possibly
// carved further) with the exact `hull` (provenance kept) of the `views` it was built from.
// Of `options`: lambda, the ballooning, the inner offset and the surface extraction (no
// silhouette steps). Fails as data like VolumetricGraphCut; CheckError without provenance.
ExactConstraintCutResult ExactConstraintCut(const VoteVolume& votes, const VoxelGrid& hull_cells,
                                            const PolyhedralHullResult& hull,
                                            const CutSilhouettes& views,
                                            const VolumetricGraphCutOptions& options,
                                            const Progress* cancel = nullptr);

}  // namespace silnet::aggregator
