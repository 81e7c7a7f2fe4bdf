#pragma once
// The exact hull's mesh from its traced vertices and edges (hull_edges.h; EPVH's third step):
// each cone face's edges, oriented so the face lies on their left, close into loops (outer
// loops counter-clockwise, holes clockwise), which are triangulated in the face's plane
// without extra points (loop_triangulation.h). Neighbouring faces share their edges' vertices
// by construction, so the mesh is closed when the graph is complete.
//
// The polyhedral hull's first way to its mesh (polyhedral_hull.h); the tests compare it with
// the mesh of the face-by-face sweeps.

#include <string>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/hull_edges.h"
#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// The mesh, or why there is none.
struct TracedHullMesh {
  bool success = false;
  std::string reason;  // when !success
  TriangleMesh mesh;   // vertices as in the graph, triangles outward
  size_t faces = 0;    // cone faces with a part on the hull
  size_t loops = 0;    // their boundary loops
};

// Assembles the mesh of `graph` (traced on `set`). Fails, naming the face, where a face's
// edges do not close into loops or its loops cannot be triangulated; the mesh is not checked
// here for being closed (mesh_check.h).
TracedHullMesh AssembleTracedHull(const ConePlaneSet& set, const HullEdgeGraph& graph);

}  // namespace silnet::aggregator
