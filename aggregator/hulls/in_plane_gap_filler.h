#pragma once
// Closes the gaps the exact polyhedral hull's assembly can leave where neighbouring cone
// faces, each swept on its own in floating point, decide a near-degenerate configuration
// (four or more cone planes nearly meeting in one point) differently: one face stops its
// region at a line its neighbours do not see there, so the mesh gets a boundary loop. When
// every vertex of such a loop lies on one common cone plane (as named by the planes meeting
// there), the loop bounds a piece of that plane's face (or a slit of no width along one of its
// edges) and is filled with triangles in that plane, which is what the face's region would
// have held had the decisions agreed.

#include <cstddef>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// What FillInPlaneGaps found and did.
struct GapFilling {
  size_t loops = 0;   // boundary loops traced
  size_t filled = 0;  // loops filled in a plane all their vertices share
  double area = 0;    // of the triangles added (square metres)
  double widest = 0;  // mean width of the widest filled loop, 2 area / perimeter (metres)
};

// Traces the mesh's boundary (edges used by one triangle) into loops and fills each loop whose
// vertices share a plane (`vertex_planes[v]`: the sorted planes mesh vertex v lies on) with the
// least-area triangulation that runs against the loop, so orientation stays consistent, using
// no edge the mesh already has. A boundary that does not form simple loops, and loops without
// a common plane, are left open for the caller's manifold check to report.
GapFilling FillInPlaneGaps(const std::vector<std::vector<int>>& vertex_planes, TriangleMesh& mesh);

}  // namespace silnet::aggregator
