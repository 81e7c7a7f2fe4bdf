#pragma once
// The visual hull the stereo job cuts its model from: the exact polyhedral hull of the
// silhouettes that lie inside their images, or a voxel hull where the exact one cannot be
// closed, carved on the lattice by the silhouettes the image border cuts.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/voxel_grid.h"
#include "aggregator/stereo/volumetric_graph_cut.h"

namespace silnet::aggregator {

// What carving by the silhouettes the image border cuts did to a hull on the lattice.
struct BorderCarving {
  size_t carved = 0;    // cells cleared by a border view's background
  size_t restored = 0;  // of which given back to cover another view's silhouette
};

// Clears the occupied cells of `grid` whose centres a view of `border` sees at a background
// pixel (VoxelCentreInHull's rule: a centre projecting outside a view's image is not carved by
// it), so views whose silhouettes the image border cuts still bound the subject inside their
// images. Then, on the ray of every pixel at least `margin_px` inside a silhouette of
// `bounded` (InnerSilhouettePixels) that would otherwise meet no occupied cell, gives back the
// one cleared cell the border views see least far outside their silhouettes (unless a cell
// given back for another ray already lies on it): where the views disagree, a silhouette pixel
// wins over a border view's background (a shadow on the subject read as backdrop), at the
// least cost in the border views' outer pixels. Cameras are undistorted.
BorderCarving CarveByBorderViews(const CutSilhouettes& border, const CutSilhouettes& bounded,
                                 double margin_px, VoxelGrid* grid);

// The exact polyhedral hull of `views`, or, when it cannot be closed, the voxel hull carved at
// one pixel footprint (the mean at the centre of the viewing cones' box) on `threads` threads
// (0 = all), with a warning appended to `warnings` and logged. Where the cameras and the
// silhouettes disagree by about a pixel (real photographs with their given cameras), the exact
// hull misses silhouette pixels >= 1 px inside their outlines, which no model inside it can
// cover, while a silhouette-consistent model may reach up to 1 px beyond an outline: when it
// misses more than `kWidenedHullMissedShare` of them, it is built again from covering contours
// (covering_contour.h) `kWidenedCoverOffsetPx` beyond the pixel centres, whose chords pass the
// first background pixel centres by at most `kWidenedCoverSlackPx`, or, where those do not
// close, from the silhouettes grown by one pixel (3x3) with contours `kWidenedGrownOffsetPx`
// from the grown pixel centres; that hull is taken if it misses fewer (a warning says what was
// done). Both keep clear of the pixel centres 2 px outside (measured on the Middlebury rings
// and simulated stills with a view 1-3 px off).
// Views taken from another's viewpoint (the Middlebury temple ring repeats its first) are named in
// a warning too, their silhouettes intersected into one cone. Failure is data, as
// ComputePolyhedralHull's. With `keep_provenance` the result carries the hull's provenance
// (the exact silhouette constraints need it).
inline constexpr double kWidenedHullMissedShare = 1e-3;
inline constexpr double kWidenedCoverOffsetPx = 1.3;
inline constexpr double kWidenedCoverSlackPx = 0.35;
inline constexpr double kWidenedGrownOffsetPx = -0.3;
PolyhedralHullResult ComputeStereoHull(const CutSilhouettes& views, int threads,
                                       std::vector<std::string>* warnings,
                                       bool keep_provenance = false);

}  // namespace silnet::aggregator
