#pragma once
// The full outline of a silhouette for visual hulls: polygons with holes, at sub-pixel
// precision, simplified to a tolerance (DESIGN.md "Contour").
//
// Outer rings are in positive orientation (like SilhouetteHull), holes in negative
// orientation. By default points lie on the estimated silhouette boundary, half a lattice
// step outside the boundary pixel centres (0.5 px across axis-aligned edges, 0.35 px across
// diagonal ones); options can place them further out and smooth the pixel staircase first.
// Plain Douglas-Peucker may cut the outline inside some boundary pixel centres; the covering
// simplification (covering_contour.h) never does.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace silnet {

// One connected silhouette region.
struct ContourPolygon {
  std::vector<Eigen::Vector2f> outer;
  std::vector<std::vector<Eigen::Vector2f>> holes;
};

// All regions of a silhouette.
struct SilhouetteContours {
  std::vector<ContourPolygon> polygons;
  // Number of outline points in all rings.
  size_t PointCount() const;
  // Area covered (outer minus holes), square pixels.
  double Area() const;
};

// Options of contour extraction.
struct ContourOptions {
  double tolerance_px = 0.5;        // Douglas-Peucker simplification tolerance
  double min_region_area = 4.0;     // drop regions smaller than this (square pixels)
  double min_hole_area = 4.0;       // drop holes smaller than this
  double boundary_offset_px = 0.5;  // outline's distance outside the boundary pixel centres
  int smoothing_passes = 0;         // [1 2 1] / 4 passes along the ring before simplifying
  // Simplify conservatively (covering_contour.h): the boundary pixel centres lie at least
  // `cover_margin_px` inside the outline's edges. tolerance_px is then not used, and an
  // outline point takes its smoothed position only where that lies farther out.
  bool cover_pixel_centres = false;
  double cover_margin_px = 0.1;
  double cover_background_slack_px = 0.15;  // see CoveringOptions::background_slack_px
};

// Extracts the outline of the nonzero pixels of a CV_8UC1 mask.
SilhouetteContours ExtractContours(const cv::Mat& mask, const ContourOptions& options = {});

// Signed area of a ring (positive for positive orientation), square pixels.
double RingArea(const std::vector<Eigen::Vector2f>& ring);

// True if the point lies inside the silhouette described by the contours (even-odd rule).
bool ContoursContain(const SilhouetteContours& contours, const Eigen::Vector2f& point);

}  // namespace silnet
