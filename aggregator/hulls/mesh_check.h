#pragma once
// Topological checks of a triangle mesh: is it the closed, oriented, manifold surface of a
// solid?

#include <cstddef>
#include <string>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// What the check found; `closed_manifold` is true iff every count below is zero.
struct MeshCheck {
  bool closed_manifold = false;
  std::string reason;                // first problem found, empty when closed_manifold
  size_t bad_indices = 0;            // triangles with an out-of-range or repeated vertex
  size_t open_edges = 0;             // edges used by one triangle
  size_t non_manifold_edges = 0;     // edges used by more than two triangles
  size_t misoriented_edges = 0;      // edges both of whose triangles run the same way
  size_t non_manifold_vertices = 0;  // vertices whose triangles form more than one fan
  long euler_characteristic = 0;     // V - E + F over referenced vertices (2 per sphere)
};

// Checks that every edge is shared by exactly two triangles that traverse it in opposite
// directions (closed and consistently oriented) and that the triangles around every
// vertex form a single fan (manifold vertices). An empty mesh passes.
MeshCheck CheckClosedManifold(const TriangleMesh& mesh);

}  // namespace silnet::aggregator
