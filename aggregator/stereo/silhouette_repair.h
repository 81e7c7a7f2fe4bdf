#pragma once
// The silhouette step of the graph cut (thesis 7.4.2, used here on the uniform lattice): the
// cut surface is projected into every view, and each silhouette pixel at least `margin_px`
// inside the outline that the surface misses adds one interior cell on its viewing ray; the
// cut is then solved again with those cells tied to the source. Given the face steps from the
// cut's interior (steps_to_interior.h), the cell is the ray's hull cell nearest the interior
// within their bound, and the cells between them are added too, so the cell joins the model
// where the ray grazes it (where the pixel's rim lies if the model is about right) instead of
// floating. Otherwise, or where the ray passes no cell within the bound (a part the cut lost
// entirely), it is the hull cell on the ray with the most photo-consistency votes (the surface
// the views agree on), or, where no cell on it has votes, the middle of the ray's first run
// through the hull (the thin part the pixel sees). Pixels outside the silhouettes cannot be
// covered: the cut stays in the hull.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/vote_volume.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The cells one silhouette step adds and how many pixels asked for them.
struct SilhouetteRepair {
  std::vector<size_t> cells;  // lattice indices, ascending, no duplicates
  size_t missed_pixels = 0;   // inner silhouette pixels the surface misses, all views
  size_t unreachable = 0;     // of which whose ray meets no hull cell (left as they are)
  size_t joined = 0;          // of which whose cell was chosen (and bridged) next to the interior
};

class StepsToInterior;

// The cells to tie to the source so that `surface` (the current cut, closed) covers every
// inner pixel of `masks` (CV_8UC1, non-zero = silhouette) seen by undistorted `cameras`
// (CheckError on distortion or mismatched sizes). `hull` and `votes` share the lattice, and
// `steps` (may be null: cells chosen by votes only) was computed on it from the cut's interior.
SilhouetteRepair FindSilhouetteRepair(const TriangleMesh& surface, const VoxelGrid& hull,
                                      const VoteVolume& votes,
                                      const std::vector<CameraModel>& cameras,
                                      const std::vector<cv::Mat>& masks, double margin_px,
                                      const StepsToInterior* steps = nullptr);

}  // namespace silnet::aggregator
