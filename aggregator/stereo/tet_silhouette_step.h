#pragma once
// The silhouette step of the adaptive stereo (thesis 7.4.2): the cut's surface is rendered into
// every view; a background pixel (at least `margin_px` outside the outline) that the surface
// covers has a viewing ray that must not meet the object, so every interior cell on it is
// made exterior; a silhouette pixel (at least `margin_px` inside) that the surface misses has
// a viewing ray that must meet the object, so one cell on it is made interior: the cell at
// the middle of the ray's first stretch inside the visual hull (cells neither labelled nor
// made exterior). The cut is updated and this repeated for a few rounds or until no pixel is
// wrong. Cells made interior are never made exterior and the other way round.
// (The thesis picks the cell between the ray's front- and back-facing photo-consistency peaks;
// the middle of the hull's stretch is the same cell for thin parts, where nearly all the
// missed pixels are.)

#include <cstddef>
#include <vector>

#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/tet_cell_labels.h"
#include "aggregator/stereo/tet_graph_cut.h"
#include "aggregator/stereo/tet_point_locator.h"

namespace silnet::aggregator {

// Settings of the step.
struct TetSilhouetteOptions {
  int rounds = 4;        // cuts after the first at most
  int pixel_stride = 2;  // every this many missed pixels per row and column
  double margin_px = 1.0;
  double ray_step = 0.0;  // metres, > 0: sampling of the rays
};

// What the step did.
struct TetSilhouetteStats {
  std::vector<size_t> missed;   // missed inner pixels before each round and after the last
  std::vector<size_t> covered;  // covered outer pixels likewise
  size_t forced = 0;            // cells made interior
  size_t forced_out = 0;        // cells made exterior
};

// Runs the step on `cut` (of `mesh` with `labels`).
TetSilhouetteStats EnforceSilhouettesOnTets(TetGraphCut* cut, const TetMesh& mesh,
                                            const std::vector<CellLabel>& labels,
                                            const TetPointLocator& locator,
                                            const std::vector<StereoView>& views,
                                            const TetSilhouetteOptions& options);

}  // namespace silnet::aggregator
