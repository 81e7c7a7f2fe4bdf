#pragma once
// The connected pieces of a triangle mesh and the genus of each: how many separate parts a
// model has and how many handles (through-holes) each part has.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// One piece: triangles connected through shared vertices.
struct MeshComponent {
  size_t triangles = 0;
  size_t vertices = 0;
  long euler_characteristic = 0;  // V - E + F of the piece
  // (2 - chi) / 2: the number of handles when the piece is a closed, oriented 2-manifold
  // (CheckClosedManifold); meaningless otherwise.
  long genus = 0;
};

// The piece of each triangle of `mesh` (triangles connected through shared vertices), pieces
// numbered 0.. in the order of their smallest vertex index, and their number in `pieces`.
// Triangles with a repeated or out-of-range vertex belong to none (-1).
std::vector<int32_t> TrianglePieces(const TriangleMesh& mesh, size_t* pieces);

// The mesh's pieces, the one with the most triangles first. Triangles with a repeated or
// out-of-range vertex are ignored.
std::vector<MeshComponent> MeshComponents(const TriangleMesh& mesh);

}  // namespace silnet::aggregator
