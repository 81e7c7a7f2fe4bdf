#pragma once
// The last silhouette step of a stereo surface (thesis 7.4.2-7.4.3, below the cells' size):
// inner silhouette pixels (model_evaluation.h) the surface still misses although a model
// consistent with the other views could cover them (uncoverable_pixels.h) are reached by
// moving one vertex each onto the pixel's viewing ray, to the point of its coverable reach
// nearest the vertex, a little beyond the pixel centre. Every round's moves are checked in
// every view: moves near an outer pixel they newly cover, or an inner pixel they newly miss,
// are undone (over a wider neighbourhood each time, all of them at last), so the surface never
// covers an outer pixel it did not cover before, nor misses an inner pixel it covered. Only
// vertices move: the mesh stays closed, oriented and manifold as it was.

#include <cstddef>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// Settings of the step.
struct PixelReachOptions {
  int rounds = 6;                          // 0: the surface is left as it is
  double search_px = 3.0;                  // a pixel takes a vertex projecting this near it
  double max_move_footprints = 2.0;        // no vertex ends farther than this from where it was
  double beyond_px = 0.02;                 // past the pixel centre, away from where the vertex was
  double margin_px = kSilhouetteMarginPx;  // of the inner and outer pixels
  int threads = 0;                         // rendering the views

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// What the step did.
struct PixelReachStats {
  size_t rounds = 0;
  size_t missed_before = 0;     // inner pixels missed, over all views, before the step
  size_t coverable_before = 0;  // of which coverable
  size_t moved = 0;             // vertex moves kept
  size_t undone = 0;            // moves undone by the checks
  size_t missed_after = 0;      // inner pixels missed after it
  double seconds = 0;
};

// Reaches the coverable inner pixels `mesh` misses in `views` (pinhole cameras), the object's
// pixels `footprint` metres wide (> 0).
PixelReachStats ReachMissedPixels(const std::vector<StereoView>& views, double footprint,
                                  const PixelReachOptions& options, TriangleMesh* mesh);

}  // namespace silnet::aggregator
