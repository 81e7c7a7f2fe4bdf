#pragma once
// Red-green subdivision of a triangle mesh (the 2D scheme the thesis's local refinement,
// 7.4.3, remeshes with): the edges a predicate picks are bisected; a triangle with all three
// edges bisected is split red into four similar triangles, a triangle with one edge bisected
// green into two, and a triangle with two is closed to red by bisecting its third edge. Every
// edge is bisected once, at one midpoint shared by both its triangles, so a closed, oriented
// manifold stays one.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// True if the edge between vertices a and b must be bisected.
using EdgeSplitTest = std::function<bool(int32_t a, int32_t b)>;

// What one subdivision did.
struct SubdivisionStats {
  size_t edges_split = 0;  // edges the test picked
  size_t closure = 0;      // further edges bisected to close triangles to red
  size_t red = 0, green = 0;
};

// Subdivides `mesh` in place once: new vertices are appended at edge midpoints (their ids
// from mesh->vertices.size() on) and the triangles replaced; `parents`, if given, receives the
// two ends of the edge each new vertex halves, in the new vertices' order. Nothing changes
// (and false is returned) if no edge is picked or the result would have more than
// `max_triangles`.
bool SubdivideLongEdges(TriangleMesh* mesh, const EdgeSplitTest& split, size_t max_triangles,
                        SubdivisionStats* stats = nullptr,
                        std::vector<std::array<int32_t, 2>>* parents = nullptr);

}  // namespace silnet::aggregator
