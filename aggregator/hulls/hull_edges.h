#pragma once
// The exact hull's edges and vertices traced from its viewing edges (thesis 4.2; EPVH's second
// step). Every vertex of the hull lies on three cone faces and, in generic position, has one
// edge along each pair of them that belongs to two views (the pair of one view is its viewing
// edge). From each vertex found, starting with the viewing edges' ends, each such edge is
// followed along the line where the two faces meet, away from the third face, up to the first
// point where it leaves either face's wedge or another view's cone (cone_line_stretches.h):
// the next vertex. Each edge is kept once, traced from whichever end is found first (or from
// both, where one round of the tracing finds both). Every vertex is named by its three cone
// planes, so the faces that meet there share it without tolerances.
//
// The polyhedral hull (polyhedral_hull.h) builds its mesh from these (traced_hull_mesh.h);
// the tests compare them with the vertices and edges of its face-by-face sweeps.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/viewing_edges.h"
#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Three cone planes' indexes, ascending: the name of the hull vertex where they meet.
using PlaneTriple = std::array<int, 3>;

// The name of the vertex of planes a, b and c.
PlaneTriple SortedPlanes(int a, int b, int c);

// The direction within face `face`'s plane into the side of plane `bound` that the face keeps:
// its wedge (`bound` the plane before or after it, whose ray through the shared contour point
// bounds the wedge) or another view's cone (`bound` a face of it). A line in the plane along
// `d` moves into that side where its dot product with `d` is positive.
Eigen::Vector3d IntoFaceSide(const ConePlaneSet& set, int face, int bound);

// A vertex of the hull: where three cone planes meet.
struct HullEdgeVertex {
  PlaneTriple planes{};
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// An edge of the hull between vertices `from` and `to`, on cone planes `a` < `b` (of one view
// for a viewing edge, of two views otherwise).
struct HullEdge {
  int a = -1, b = -1;
  int from = -1, to = -1;
};

// The hull's vertices and edges, and what tracing them cost.
struct HullEdgeGraph {
  std::vector<HullEdgeVertex> vertices;
  std::vector<HullEdge> edges;
  size_t viewing_edges = 0;  // of `edges`, those along a contour vertex's ray
  size_t traced = 0;         // edges of two views' faces traced (the others are viewing edges)
  size_t open_ends = 0;      // edge ends the bounds box cut (none for bounds around the hull)
};

// Traces the hull's edges from `viewing_edges` (ComputeViewingEdges of the same `cameras`,
// `set` and `bounds`) on `threads` threads. Deterministic: vertices and edges in the order
// they are found, whatever the number of threads.
HullEdgeGraph TraceHullEdges(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                             const WorldBox& bounds, const std::vector<ViewingEdge>& viewing_edges,
                             int threads = 1);

}  // namespace silnet::aggregator
