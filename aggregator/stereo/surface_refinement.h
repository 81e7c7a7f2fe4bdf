#pragma once
// Local refinement of a stereo surface (thesis 7.4.3): the graph cut's surface, exact only to
// its cells, is deformed by texture and silhouette forces along the vertex normals
// (surface_forces.h), smoothed by Taubin's filter (which does not shrink it) and remeshed by
// red-green subdivision (triangle_remeshing.h) wherever an edge is longer than `max_edge_px`
// in its best view. Each vertex keeps within a box of +-max_shift around where it (or, for a
// new vertex, the edge it halves) started, so the result stays near the cut; the inner
// silhouette pixels the cut covered stay covered (coverage_restore.h), and those it missed are
// reached where a consistent model can cover them (missed_pixel_reach.h). Moves and
// subdivision keep a closed, oriented manifold one.

#include <cstddef>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/missed_pixel_reach.h"
#include "aggregator/stereo/patch_photo_consistency.h"
#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/surface_forces.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the refinement; lengths in footprints (the mean size of a pixel at the object).
struct SurfaceRefinementOptions {
  int iterations = 6;              // 0: the surface is returned as it is
  double search_footprints = 2.0;  // texture offsets searched in +-this, then +-half of it
  double search_step_footprints = 0.5;
  double min_score = 0.7;             // texture force only where a patch scores this
  int curvature_rounds = 5;           // VertexCurvatures
  double texture_rate = 0.5;          // fraction of the texture offset moved per iteration
  double max_step_footprints = 1.0;   // per iteration
  double max_shift_footprints = 3.0;  // per axis, in all
  double max_edge_px = 2.0;           // remeshing; 0: no remeshing
  size_t max_triangles = 4'000'000;   // remeshing stops before this
  int smoothing_pairs = 3;            // Taubin lambda|mu pairs per iteration
  double smoothing_lambda = 0.5;
  double smoothing_mu = -0.53;
  PatchOptions patch;  // of the texture force's patches (the job builds its scorer from them)
  SilhouetteForceOptions silhouettes;
  int restore_rounds = 6;  // RestoreCoverage of the silhouette pixels the surface covered
  // Then the coverable inner pixels still missed reached (missed_pixel_reach.h; its threads
  // are these).
  PixelReachOptions reach;
  int threads = 0;

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// What the refinement did.
struct SurfaceRefinementStats {
  size_t vertices_in = 0, triangles_in = 0;
  size_t vertices = 0, triangles = 0;
  size_t split_edges = 0;         // by remeshing, closure included
  size_t textured = 0, rims = 0;  // vertices moved by each force in the last iteration
  double mean_shift = 0;          // metres: mean distance of the vertices from their start
  size_t restored = 0;            // vertices put back to keep the silhouettes covered
  size_t still_uncovered = 0;     // inner silhouette pixels the input covered and the result not
  PixelReachStats reach;          // the last step's
  double seconds = 0;
  bool cancelled = false;
};

// The refined `surface` (closed and oriented, from the cut) seen in `views` with patches
// scored by `scorer` (of the same views), `footprint` metres per pixel (> 0). `progress` (may
// be null) gets one item per iteration and is polled between them: on cancellation the
// surface as far as it got is returned and stats->cancelled set.
TriangleMesh RefineSurface(const TriangleMesh& surface, const std::vector<StereoView>& views,
                           const PatchScorer& scorer, double footprint,
                           const SurfaceRefinementOptions& options,
                           SurfaceRefinementStats* stats = nullptr, Progress* progress = nullptr);

}  // namespace silnet::aggregator
