#pragma once
// One face of the exact polyhedral visual hull (thesis 4.2, EPVH): the part of one viewing-cone
// face (the wedge from a camera centre through one contour edge) that lies inside every other
// camera's viewing cone.
//
// The wedge is parametrised by a chart (lambda, w): lambda in [0, 1] runs along the contour
// edge p -> q, w is the inverse depth in the face's camera, X(lambda, w) = C + d(lambda) / w
// with d(lambda) the ray through p + lambda (q - p) scaled to unit depth. Every other camera
// maps the chart by a homography, so another view's contour edges are straight lines in the
// chart, vertical chart lines are viewing rays of the face's camera (their pieces inside all
// cones are the viewing edges at lambda = 0 and 1) and the lines' crossings are the triple
// points. The region is found by a sweep over lambda: between events (contour vertices and
// crossings of boundary lines) it is a union of trapezoids, each bounded below and above by
// one line (a cone-intersection edge).

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Another view's contour edge seen in a face's chart: inside that silhouette where
// coefficients . (lambda, w, 1) > 0; it spans [lambda_lo, lambda_hi] inside the chart box.
struct ChartLine {
  int plane = -1;
  int view = -1;
  Eigen::Vector3d coefficients;
  double slope = 0, intercept = 0;  // w = slope * lambda + intercept along the line
  double lambda_lo = 0, lambda_hi = 0;
  double w_lo = 0, w_hi = 0;    // the span's w-range
  double bottom_crossing = -1;  // lambda where it crosses w = w_min, or -1

  // The w of the line at `lambda`.
  double WAt(double lambda) const { return slope * lambda + intercept; }
};

// A point (lambda, w) where the region's structure may change: a contour vertex between
// planes `first` and `second` of another view, or a crossing of two views' lines.
struct ChartEvent {
  double lambda = 0;
  double w = 0;
  int first = -1, second = -1;
};

// Between two lambdas the region is a list of w-intervals, each between two lines (indices
// into FaceRegion::lines), listed from low to high w: FaceRegion::intervals[first, first +
// count).
struct ChartSlab {
  double lambda_a = 0, lambda_b = 0;
  int first = 0, count = 0;
};

// The face's region, or why it could not be computed.
struct FaceRegion {
  bool success = false;
  std::string reason;
  int plane = -1;
  Eigen::Vector3d centre, d_p, d_q;  // X(lambda, w) = centre + (d_p + lambda (d_q - d_p)) / w
  double w_min = 0, w_max = 0;
  std::vector<ChartLine> lines;
  std::vector<ChartEvent> events;  // sorted by lambda; slab boundaries are event lambdas
  std::vector<ChartSlab> slabs;    // sorted, contiguous over [0, 1], merged where equal
  std::vector<std::pair<int, int>> intervals;  // the slabs' (lower line, upper line), in order

  // The world point of chart point (lambda, w).
  Eigen::Vector3d Point(double lambda, double w) const {
    return centre + (d_p + lambda * (d_q - d_p)) / w;
  }
};

// Computes the region of cone plane `plane` inside every other camera's cone, within `box`
// (which must contain the hull and lie in front of every camera). Fails as data when the
// box is behind a camera or the region reaches the box.
FaceRegion ComputeFaceRegion(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                             int plane, const WorldBox& box);

}  // namespace silnet::aggregator
