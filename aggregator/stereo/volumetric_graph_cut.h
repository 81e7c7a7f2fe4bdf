#pragma once
// The baseline volumetric graph cut (thesis 5.4.1, after Vogiatzis et al.): the surface
// minimising E(S) = integral over S of rho(x) dA - ballooning * volume(S), rho = the
// photo-consistency cost exp(-lambda * votes) of 6.8.1, among the surfaces between the visual
// hull and an inner offset surface. Stages: the hull's distance transform and the lattice's
// roles, the flow graph (stereo_graph.h), Boykov-Kolmogorov max flow (max_flow.h), the labels,
// and the surface of the interior cells (surface_extraction.h). Silhouette steps (thesis
// 7.4.2, silhouette_repair.h) then tie a cell to the source for every silhouette pixel the
// surface misses and update the cut, until the model covers its silhouettes; the graph is
// built and solved once, each step re-solves incrementally from the previous flow and search
// trees (max_flow.h) with the same result as rebuilding it with the cells as pockets. (The exact
// constraints of 6.4-6.7, Formulation I and II, are not built yet.)

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/stereo_graph.h"
#include "aggregator/stereo/surface_extraction.h"
#include "aggregator/stereo/vote_volume.h"
#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the graph cut.
struct VolumetricGraphCutOptions {
  double lambda = 1.0;                 // cost per face exp(-lambda * votes) (6.8.1), > 0
  double inner_offset_fraction = 0.4;  // T of 6.6: pockets deeper than T * d_max, in (0, 1)
  double inner_offset_cells = 0;       // > 0: fixed inner offset depth in cells instead of T
  double ballooning = 0;               // volume reward per interior cell (5.4.1), >= 0
  bool extract_surface = true;         // also build the surface mesh
  int silhouette_rounds = 0;           // silhouette steps (thesis 7.4.2), >= 0
  double silhouette_margin_px = 1.0;   // pixels this far inside the outline must be covered
  int silhouette_join_steps = 0;       // > 0: cells within this many face steps of the cut's
                                       // interior are chosen first and joined to it (silhouette_
                                       // repair.h), at most StepsToInterior::kMaxSteps; 0: by votes
  SurfaceExtractionOptions surface;

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The silhouettes the silhouette step makes the cut consistent with: undistorted cameras
// (those the hull was built from) and one mask each (CV_8UC1, non-zero = silhouette).
struct CutSilhouettes {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
};

// Sizes and times of one run.
struct VolumetricGraphCutStats {
  int silhouette_rounds = 0;  // silhouette steps that re-solved the cut or re-pinned it
  size_t forced_cells = 0;    // cells they tied to the source
  size_t pinned_cells = 0;    // cells on missed pixels' rays whose corners the surface keeps
  size_t joined_pixels = 0;   // missed pixels whose cell was chosen next to the interior
  std::vector<size_t> missed_pixels_per_round;  // inner pixels missed before each step
  double seconds_silhouette_step = 0;           // projecting and choosing cells
  size_t lattice_cells = 0;
  size_t hull_cells = 0;
  size_t pocket_cells = 0;        // tied to the source
  size_t nodes = 0;               // graph nodes: free cells before silhouette steps
  size_t n_links = 0;             // edges between nodes (two arcs each)
  size_t t_link_faces = 0;        // faces of nodes with pocket or outside cells
  double max_depth_cells = 0;     // d_max of the hull
  double inner_offset_cells = 0;  // the depth used
  double cut_cost = 0;            // capacity of the final minimum cut incl. forced faces
  size_t interior_cells = 0;      // cells labelled interior
  size_t graph_bytes = 0;         // max-flow library's nodes and arcs
  size_t lattice_bytes = 0;       // roles, node index, labels, distances
  double seconds_distance = 0;    // distance transform and roles
  double seconds_build = 0;       // flow graph (built once)
  double seconds_max_flow = 0;    // Boykov-Kolmogorov (first solve + incremental re-solves)
  double seconds_labels = 0;      // interior grid from the cut (all rounds)
  double seconds_surface = 0;     // surface mesh (all rounds)
  size_t surface_triangles = 0;

  // One line with the sizes and times, for logs.
  std::string Brief() const;
};

// The labelled cells and their surface, or why there are none.
struct VolumetricGraphCutResult {
  bool success = false;
  std::string reason;    // when !success
  VoxelGrid interior;    // on the vote lattice: 1 = interior (source side)
  TriangleMesh surface;  // closed, oriented, manifold (when options.extract_surface)
  VolumetricGraphCutStats stats;
};

// The lattice roles of `hull` (ClassifyLattice with the options' inner offset), with the time
// it took, the hull and pocket cells and the depths recorded in `stats`.
StereoLattice ClassifyHullCells(const VoxelGrid& hull, const VolumetricGraphCutOptions& options,
                                VolumetricGraphCutStats& stats);

// Runs the cut of `votes` inside `hull` (occupancy on exactly the votes' lattice; CheckError
// otherwise, for invalid options, and for silhouette steps without `silhouettes`). An
// empty hull, or one with no cell deeper than the inner offset, is reported as a failure.
// Once `cancel` (may be null) is cancelled it stops at its next step (after the max-flow, after
// each surface extraction) with the reason "cancelled".
VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const VoxelGrid& hull,
                                            const VolumetricGraphCutOptions& options,
                                            const CutSilhouettes* silhouettes = nullptr,
                                            const Progress* cancel = nullptr);

// The same with the hull as a closed mesh (e.g. the polyhedral visual hull), voxelised on the
// votes' lattice (cells whose centres lie inside it).
VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const TriangleMesh& hull,
                                            const VolumetricGraphCutOptions& options,
                                            const CutSilhouettes* silhouettes = nullptr,
                                            const Progress* cancel = nullptr);

}  // namespace silnet::aggregator
