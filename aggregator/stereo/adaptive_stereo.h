#pragma once
// The adaptive tetrahedral stereo (thesis ch. 7) from calibrated views and their visual hull:
//   mesh         the photo-consistency driven BCC mesh over the hull's box (adaptive_tet_mesh.h)
//   labels       exterior outside the hull, interior from the quasi-dense points' rays
//                (tet_cell_labels.h)
//   cut          the minimum cut on the mesh's dual graph (tet_graph_cut.h), its ballooning
//                raised while the cut misses much of the silhouettes
//   silhouettes  cells forced inside for missed silhouette pixels, the cut updated
//                (tet_silhouette_step.h)
//   surface      the interior's boundary made manifold and smoothed (tet_surface.h)
// The local refinement of the surface (7.4.3) follows in the stereo job, for either method
// (surface_refinement.h).

#include <cstddef>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/adaptive_tet_mesh.h"
#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/tet_cell_labels.h"
#include "aggregator/stereo/tet_graph_cut.h"
#include "aggregator/stereo/tet_silhouette_step.h"
#include "aggregator/stereo/tet_surface.h"

namespace silnet::aggregator {

// Settings of the adaptive stereo. Ray steps and the surface's vertex bound are set from the
// finest cells (half their spacing); `threads` is handed to every stage.
struct AdaptiveStereoOptions {
  AdaptiveTetMeshOptions mesh;
  CellLabelOptions labels;
  TetGraphCutOptions cut;
  TetSilhouetteOptions silhouettes;
  TetSurfaceOptions surface;
  // While the cut misses more than this share of the views' inner silhouette pixels (before
  // the silhouette step), its ballooning is multiplied by `ballooning_raise`, at most
  // `max_ballooning_raises` times. A cut that leaves out a fifth of the silhouettes has shrunk
  // from surfaces whose faces score poorly (few views, weak texture), and the silhouette
  // step's one cell per missed pixel brings back their outlines, not the volume behind them.
  double max_missed_share = 0.2;
  double ballooning_raise = 1.5;
  int max_ballooning_raises = 2;
  int threads = 0;

  // True if the mesh's, the cut's and the raise's settings make sense; otherwise false with a
  // reason naming the stage ("mesh: ...", "graph cut: ...").
  bool IsValid(std::string* reason) const;
};

// What the stages did.
struct AdaptiveStereoStats {
  std::vector<AdaptiveLevelStats> levels;
  size_t cells = 0;         // conforming tetrahedra (graph nodes)
  size_t links = 0;         // shared faces (n-links)
  size_t faces_scored = 0;  // faces given a photo-consistency cost
  size_t quasi_dense_points = 0;
  CellLabelStats labels;
  std::vector<double> missed_share;  // of the inner silhouette pixels, before each raise and after
  double ballooning_factor = 1;      // the cut's ballooning relative to the options'
  std::vector<size_t> missed;        // silhouette step: missed inner pixels per round
  std::vector<size_t> covered;       // and covered outer pixels
  size_t forced = 0;                 // cells forced inside
  size_t forced_out = 0;             // cells forced outside
  size_t repaired = 0;               // cells added to make the surface manifold
  double finest_spacing = 0;         // metres
  double seconds_mesh = 0, seconds_labels = 0, seconds_cut = 0, seconds_silhouettes = 0,
         seconds_surface = 0;
  double seconds_max_flow = 0;  // of seconds_cut, the first max-flow (the rest: face costs)
};

// The model and its figures.
struct AdaptiveStereoResult {
  bool success = false;
  std::string reason;  // when !success
  TriangleMesh surface;
  AdaptiveStereoStats stats;
};

// Runs the stages on `views` (undistorted) whose visual hull is `hull`, `footprint` metres per
// pixel at the object (> 0). An empty hull or an empty cut is a failure with a reason, and so
// is cancellation through `progress` (may be null; restarted per level of the mesh, one item
// per face sampled, then for the other four stages, one item each; polled within the mesh's
// levels, the labels and the cut's face costs, and between stages).
AdaptiveStereoResult RunAdaptiveStereo(const std::vector<StereoView>& views,
                                       const TriangleMesh& hull, double footprint,
                                       const AdaptiveStereoOptions& options,
                                       Progress* progress = nullptr);

}  // namespace silnet::aggregator
