#pragma once
// Photo-consistency by multi-hypothesis two-view matching and 3D voting (thesis 6.8.1).
//
// For every view (the reference) and each of its k proximal views (neighbour_views.h), every
// silhouette pixel of the reference (every `pixel_step`-th in x and y) is matched along its
// epipolar line in the neighbour, restricted to the depths where its viewing ray is inside the
// visual hull (the hull mesh rasterised on the vote lattice and grown by `hull_margin_cells`):
// NCC of mu x mu windows at about one pixel steps, every local maximum above a threshold kept
// and refined to sub-pixel position (epipolar_ncc_matcher.h). Each hypothesis is triangulated
// on the reference ray and adds a vote to the lattice cell it falls in, if that cell meets the
// hull. The cost of a cell is then exp(-lambda * votes) (vote_volume.h).
//
// Robustness to occlusion and to views that see a point badly comes from the voting, not from
// any visibility reasoning: a pair in which the point is occluded or seen at a grazing angle
// yields maxima at unrelated depths, and those scatter over many cells, while the pairs that
// see the true surface agree on the same few cells, from every reference view and neighbour
// that sees it. Occluded matches are outliers that do not accumulate (thesis: "treats
// occlusion as outliers during the matching process").
//
// Neighbour windows whose centre is outside the neighbour's silhouette, or with less than
// `matching.min_window_in_silhouette` of their pixels inside it, are not scored: they show
// mostly background, which looks different from every camera. Reference windows are used
// whole (a rim pixel's window may include background; its matches are then weak or wrong and
// are outvoted like occluded ones).
//
// Work items are bands of reference rows spread over `threads` threads; each thread votes into
// its own lattice of fixed-point counters (1/256 vote), summed at the end, so the result does
// not depend on the thread count or the order of the items.

#include <cstdint>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/epipolar_ncc_matcher.h"
#include "aggregator/stereo/neighbour_views.h"
#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/vote_volume.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the photo-consistency computation.
struct PhotoConsistencyOptions {
  NeighbourViewOptions neighbours;    // k proximal views per view
  EpipolarNccOptions matching;        // NCC windows and maxima along epipolar lines
  int pixel_step = 1;                 // every s-th reference pixel in x and in y
  double cell_size = 0.0;             // vote lattice cell edge, metres; 0 = from the footprint
  double cell_size_footprints = 1.0;  // with cell_size 0: this many mean pixel footprints
  int hull_margin_cells = 1;   // the rasterised hull grows by this many cells (search and votes)
  bool weight_by_ncc = false;  // a vote adds its NCC instead of 1
  int rows_per_item = 8;       // reference rows per work item
  int threads = 0;             // 0 = all cores

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// Counts and times of one computation.
struct PhotoConsistencyStats {
  size_t reference_pixels = 0;    // silhouette pixels matched, over all reference views
  size_t untextured_pixels = 0;   // silhouette pixels skipped: no texture or window off-image
  size_t searches = 0;            // (pixel, neighbour) pairs with a depth range in the hull
  size_t samples = 0;             // NCC positions along epipolar lines
  size_t scored_samples = 0;      // of which had a window inside image and silhouette
  size_t matches = 0;             // local maxima kept (triangulated hypotheses)
  size_t votes_in_hull = 0;       // matches that voted
  size_t votes_outside_hull = 0;  // matches falling outside the grown hull, dropped
  double cell_size = 0.0;         // of the lattice, metres
  double footprint = 0.0;         // mean pixel footprint at the hull's centre, metres
  double seconds_prepare = 0.0;   // images, neighbours, lattice and hull rasterisation
  double seconds_matching = 0.0;  // matching and voting
  double seconds_merge = 0.0;     // summing the threads' lattices

  // One line with the main figures.
  std::string BriefReport() const;
};

// The vote lattice, or why there is none.
struct PhotoConsistencyResult {
  bool success = false;
  std::string reason;  // when !success
  VoteVolume volume;   // covers the hull's bounding box plus the margin
  // Per cell of `volume`: 1 if the cell meets the grown hull (votes only land there).
  std::vector<uint8_t> in_hull;
  std::vector<std::vector<int>> neighbours;  // per view, the views it was matched against
  std::vector<std::string> warnings;         // e.g. a view without neighbours
  PhotoConsistencyStats stats;
};

// The mean over the views of the pixel footprint (metres per pixel) at the centre of the
// mesh's bounding box: depth there over the focal length. 0 for an empty mesh.
double MeanFootprint(const std::vector<StereoView>& views, const TriangleMesh& mesh);

// Votes of all views' pairs into a lattice over `hull` (closed, outward-oriented, world
// metres; the polyhedral visual hull of the same views). Views must be pinhole (no
// distortion). Throws InputError for invalid options. Fails as data on fewer than two views,
// distorted views, an empty hull or cancellation through `progress` (which may be null and
// gets one item per band of reference rows).
PhotoConsistencyResult ComputePhotoConsistency(const std::vector<StereoView>& views,
                                               const TriangleMesh& hull,
                                               const PhotoConsistencyOptions& options = {},
                                               Progress* progress = nullptr);

}  // namespace silnet::aggregator
