#pragma once
// The viewing edges of the exact visual hull, grouped as the thesis's 2-colouring needs them
// (6.5): every contour vertex's viewing ray contributes one or more view-edge segments to the
// hull (one holds the rim point, the others are false segments where the ray crosses the hull
// again), and each cone face's part of the hull, the view's cone strip, comes in pieces.
// Derived from the hull's provenance alone (HullProvenance: the cone faces each vertex lies
// on), without geometric tolerances.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// A connected piece of one viewing ray on the hull: a chain of mesh edges, ends ordered by
// their distance from the view's camera centre.
struct ViewEdgeSegment {
  int view = 0;
  int ray = 0;                  // the cone face whose contour edge ends at the ray's vertex
  int near_vertex = 0;          // the end nearer the camera centre
  int far_vertex = 0;           // the other end
  std::vector<int> pieces;      // the face pieces (HullViewEdges::triangle_piece) it borders
  std::vector<uint64_t> edges;  // its mesh edges (MeshEdgeKey)
};

// The segments and face pieces of every view of a hull.
struct HullViewEdges {
  std::vector<int> triangle_plane;  // per triangle, the cone face it lies on (-1: none found)
  // Per triangle, its face piece: the triangles of one cone face connected across their shared
  // edges (a face can be cut into several pieces by the other views), numbered over all faces.
  std::vector<int> triangle_piece;
  std::vector<ViewEdgeSegment> segments;  // sorted by view, ray, then distance from the camera
  // Per mesh edge (key MeshEdgeKey), its two triangles (-1 where the mesh is open there).
  std::unordered_map<uint64_t, std::array<int, 2>> edge_triangles;
};

// The key of the undirected mesh edge a-b.
uint64_t MeshEdgeKey(int a, int b);

// Finds the viewing-edge segments and the face pieces of `hull`, whose vertices are
// described by `provenance` (vertex_planes per mesh vertex, the planes); `centres` holds each
// view's camera centre.
HullViewEdges FindHullViewEdges(const TriangleMesh& hull, const HullProvenance& provenance,
                                const std::vector<Eigen::Vector3d>& centres);

}  // namespace silnet::aggregator
