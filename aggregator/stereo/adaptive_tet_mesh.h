#pragma once
// The photo-consistency driven tetrahedral mesh of the adaptive stereo (thesis 7.3.1-7.3.2):
// a BCC lattice over the visual hull's box, refined level by level where the surface may be.
// At each level the faces of the cells the last refinement made are tested for crossing
// (crossing_faces.h); a cell with a crossing face (or, beyond the thesis, one the visual
// hull's surface passes through) is active and red-refined, the rest of the mesh closed
// green around it (red_green_mesh.h), until the cells reach the finest spacing.
// Cells with no crossing face are never refined and never sampled inside, which is where the
// memory and time of a uniform lattice go.

#include <cstddef>
#include <string>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/crossing_faces.h"
#include "aggregator/stereo/patch_photo_consistency.h"
#include "aggregator/stereo/red_green_mesh.h"
#include "aggregator/stereo/stereo_views.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the adaptive mesh.
struct AdaptiveTetMeshOptions {
  double base_spacing_footprints = 16.0;   // the base lattice's cube side, pixel footprints
  double finest_spacing_footprints = 2.0;  // refine until the cube side is at most this (the
                                           // cells' edges then project to 1.7-2 px)
  double sample_spacing_footprints = 1.5;  // of the faces' sample lattices
  double min_score = 0.7;                  // T: photo-consistent samples score at least this
  double prefilter_margin = 0.15;          // see CrossingFaceOptions
  int full_orientations = 2;               // see CrossingFaceOptions
  double crossing_fraction = 0.2;          // crossing faces: this share of the samples ...
  int crossing_samples = 20;               // ... or this many are photo-consistent
  // Refine cells the visual hull's surface passes through as well (some of a face's samples
  // inside every silhouette, some not), so thin parts that are hard to match (the statue's
  // staff) get fine cells and their silhouettes can be met.
  bool refine_hull_surface = true;
  PatchOptions patch;  // the patches of the crossing test
  int threads = 0;     // 0 = every core

  // Sets the finest cube side to `footprints` and, if it is positive, the base lattice's in the
  // defaults' ratio (8 times it: three levels of halving); IsValid() judges the value.
  void SetFinestSpacing(double footprints);

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// What one level of the refinement did.
struct AdaptiveLevelStats {
  int level = 0;
  double spacing = 0.0;           // cube side of the level's red cells, metres
  size_t cells = 0;               // red cells of this level tested
  size_t faces_sampled = 0;       // faces sampled afresh (the rest inherited)
  size_t samples_scored = 0;      // lattice samples inside the silhouettes, scored
  size_t active_cells = 0;        // of the tested cells, with a crossing face
  size_t refined_cells = 0;       // red-refined, the closure's included
  double seconds = 0.0;           // the whole level
  double seconds_sampling = 0.0;  // of which the faces' photo-consistency
};

// The refined mesh and what sampling it found.
struct AdaptiveTetMesh {
  RedGreenMesh mesh;
  std::vector<OrientedPoint> points;  // the quasi-dense cloud: each sampled face's best point
  std::vector<AdaptiveLevelStats> levels;
};

// Builds the mesh over `box` (world metres) for views whose pixel footprint at the object is
// `footprint` metres. Options must be valid and footprint > 0 (CheckError otherwise).
// `progress` (may be null) is restarted for each level tested ("adaptive mesh level L (S mm)",
// one item per face sampled); when it is cancelled the build stops within the level.
AdaptiveTetMesh BuildAdaptiveTetMesh(const std::vector<StereoView>& views, const WorldBox& box,
                                     double footprint, const AdaptiveTetMeshOptions& options,
                                     Progress* progress = nullptr);

}  // namespace silnet::aggregator
