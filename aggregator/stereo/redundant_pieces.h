#pragma once
// Floating pieces a stereo model does not need. The silhouette steps tie cells inside for the
// pixels a cut misses, and where a cell does not touch the cut it becomes a small piece of its
// own; later steps and the refinement often cover the same pixels with the model's body, and
// the piece is left floating beside it, covering nothing the rest does not. This removes, the
// smallest first, every piece but the largest whose inner silhouette pixels (model_evaluation.h)
// the largest does not cover are all covered by another piece still kept. So no view misses an
// inner pixel it covered, no pixel gets covered that was not, and the mesh stays closed,
// oriented and manifold (whole pieces go; the vertices no triangle uses any more go with them).

#include <cstddef>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// What the removal did.
struct RedundantPieceStats {
  size_t pieces_before = 0;      // pieces of the mesh (mesh_topology.h)
  size_t removed = 0;            // of which removed
  size_t triangles_removed = 0;  // their triangles
  double seconds = 0;
};

// Removes the pieces of `mesh` other than its largest that no inner pixel (`margin_px` inside
// the outline) of `views` needs, rendering the views on `threads` threads (0 = all cores).
RedundantPieceStats RemoveRedundantPieces(const std::vector<StereoView>& views, TriangleMesh* mesh,
                                          double margin_px = kSilhouetteMarginPx, int threads = 0);

}  // namespace silnet::aggregator
