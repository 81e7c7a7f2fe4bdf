#pragma once
// Triangulation of a planar region given by its boundary loops, without adding points: ear
// clipping, holes joined to their outer loop by bridges first (the approach of Eberly's
// "Triangulation by ear clipping" and of mapbox's earcut, written for our loops). The exact
// hull triangulates each face this way so that neighbouring faces share exactly the hull's
// own vertices along their edges.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace silnet::aggregator {

// The triangles of a region, as indices into its loops' points taken in order (the first
// loop's points, then the second's, ...), counter-clockwise; or why there are none.
struct LoopTriangulation {
  bool success = false;
  std::string reason;  // when !success
  std::vector<std::array<int, 3>> triangles;
};

// Triangulates the region bounded by `loops`: outer boundaries counter-clockwise, holes
// clockwise, each hole inside one outer loop; loops may touch at vertices but must not cross.
// Every point is a vertex of the triangles (collinear points too, as zero-area triangles when
// nothing else is possible), and no point is added. Fails as data on loops that are not such a
// region (crossing, inverted, a hole outside every outer loop); the triangles' signed areas
// then would not add up to the region's, which is checked.
LoopTriangulation TriangulateLoops(const std::vector<std::vector<Eigen::Vector2d>>& loops);

}  // namespace silnet::aggregator
