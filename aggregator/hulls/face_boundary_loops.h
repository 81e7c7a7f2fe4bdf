#pragma once
// The boundary of one exact-hull face as closed loops of the hull's own vertices. A face's
// region (cone_face_region.h) comes as trapezoids between the lines of its chart, cut at
// every event of the sweep; their corners are hull vertices named by the planes that meet
// there, or cuts the sweep made on a line where nothing meets. Walking the trapezoids' lower
// and upper sides and dropping the cuts leaves the polygon (with holes) that the face really
// is, which the hull triangulates without extra points so that neighbouring faces share
// exactly the vertices along their common edge.

#include <vector>

namespace silnet::aggregator {

// A corner of a face's trapezoid: chart w and the hull vertex (negative for a cut the sweep
// made where no planes meet, when the cuts are not hull vertices).
struct Corner {
  double w = 0;
  int vertex = -1;
};

// One trapezoid of a face: between lines `lo` and `hi` (indices into the face's chart lines)
// over [a, b] in lambda.
struct Trapezoid {
  int lo = -1, hi = -1;
  double a = 0, b = 0;
  Corner bottom_a, bottom_b, top_a, top_b;
};

// A point of a face's boundary loop in its chart.
struct LoopPoint {
  double lambda = 0, w = 0;
  int vertex = -1;
};

// The boundary loops of the union of `trapezoids` (a face's, in sweep order: slabs contiguous
// over [0, 1] in lambda, corners shared by name between neighbouring slabs), into `loops`:
// counter-clockwise around the region in (lambda, w), holes clockwise, loops that touch at a
// vertex kept apart where they can be, the cuts (corners with a negative vertex) left out
// but for the ends of trapezoid sides on the boundary inside the chart (the sides of a slab
// sliver where a line too short for the sweep was left out; the caller gives them positions),
// and without the points where a loop repeats a point or folds back on itself (a zero-area
// spike such a sliver leaves), measured with w scaled to [0, 1] over `w_range`.
// Loops without area (a sliver of a face) are left out. False if the union's boundary is not
// a set of closed loops: a boundary line that ends where none continues.
bool FaceBoundaryLoops(const std::vector<Trapezoid>& trapezoids, double w_range,
                       std::vector<std::vector<LoopPoint>>& loops);

}  // namespace silnet::aggregator
