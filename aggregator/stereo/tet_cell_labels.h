#pragma once
// Hard labels of the adaptive mesh's cells before the graph cut (thesis 7.3.3). A cell whose
// centroid some view sees outside its silhouette is outside the visual hull: exterior. The
// quasi-dense points vote along their rays to the views that scored them (a point seen from
// a camera has free space between them), each ray until it leaves the hull: inside the hull, cells
// that were never refined to the finest level (no surface was found through them) and received no
// more votes than the `interior_percentile` of such cells are interior; those with at least the
// `exterior_percentile`'s votes (and `min_exterior_votes`) are exterior. The rest are free
// for the cut. Labels are hard constraints, so both are given sparingly.

#include <cstdint>
#include <string>
#include <vector>

#include "aggregator/stereo/crossing_faces.h"
#include "aggregator/stereo/patch_photo_consistency.h"
#include "aggregator/stereo/red_green_mesh.h"
#include "aggregator/stereo/tet_surface.h"
#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// A cell's label.
enum class CellLabel : uint8_t { kFree = 0, kInterior = 1, kExterior = 2 };

// Settings of the labelling.
struct CellLabelOptions {
  double interior_percentile = 5;  // of the votes of coarse cells inside the hull
  // Likewise for exterior cells; 100 (the default) leaves none: on the simulated statue the
  // rays of wrong quasi-dense points made cells inside the torso exterior at the 95th
  // percentile, and the cut left bubbles there (accuracy 4.0 instead of 1.8 footprints).
  double exterior_percentile = 100;
  int min_exterior_votes = 3;
  double ray_step = 0.0;   // metres, > 0: the scale of the point location that starts the
                           // rays' walks (half the finest cell)
  double ray_start = 0.0;  // metres: rays start this far from their point towards the camera
  // metres: a ray crossing a cell over less than this gives it no vote. A quasi-dense point
  // lies a footprint or so off the surface, so its rays graze the cells along the surface;
  // counting every graze took the ballooning (tet_graph_cut.h) from the cells just inside
  // the temple's surface, and its first cut shrank to the interior labels (13 k -> 173 k cells
  // forced by the silhouettes, the cut 2.2 times slower).
  double min_chord = 0.0;
  int threads = 0;
};

// Counts of the labelling.
struct CellLabelStats {
  size_t outside_hull = 0, interior = 0, exterior_by_votes = 0, free = 0;
  size_t rays = 0;
};

// Labels of the conforming mesh's tetrahedra (`faces` from SortedCellFaces(mesh), `levels[t]`
// the red level each came from, `finest` the finest level). With `votes`, also the number of
// rays that crossed each cell. Once `cancel` (may be null) is cancelled it stops early: the
// labels are then not to be used.
std::vector<CellLabel> LabelCells(const TetMesh& mesh, const std::vector<CellFace>& faces,
                                  const std::vector<int>& levels, int finest,
                                  const PatchScorer& scorer,
                                  const std::vector<CameraModel>& cameras,
                                  const std::vector<OrientedPoint>& points,
                                  const CellLabelOptions& options, CellLabelStats* stats,
                                  std::vector<uint32_t>* votes = nullptr,
                                  const Progress* cancel = nullptr);

}  // namespace silnet::aggregator
