#pragma once
// Surfaces of sets of cells of a tetrahedral mesh: the faces between a set ("interior") and
// the rest, oriented outwards; the set grown where that surface pinches (an edge with more
// than two faces, a vertex whose faces form more than one fan), so the surface is a closed
// 2-manifold; and the manifold smoothed by Taubin's filter within a bound of the cells.

#include <array>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/bcc_lattice.h"

namespace silnet::aggregator {

// A face of a cell: its sorted vertex ids, the cell, the cell's corner opposite it.
struct CellFace {
  std::array<int32_t, 3> ids{};
  int32_t cell = 0;
  int8_t opposite = 0;
  bool operator<(const CellFace& o) const { return ids < o.ids || (ids == o.ids && cell < o.cell); }
};

// Every face of every cell, sorted: a face two cells share is two consecutive entries.
std::vector<CellFace> SortedCellFaces(const TetMesh& mesh);

// The faces between the cells with interior[cell] != 0 and the others (or the mesh's outside),
// oriented away from the interior; vertices renumbered. `faces` from SortedCellFaces(mesh).
TriangleMesh InteriorBoundary(const TetMesh& mesh, const std::vector<CellFace>& faces,
                              const std::vector<uint8_t>& interior);

// Adds to the interior every cell around the boundary's non-manifold edges and vertices until
// it has none; cells with avoid[cell] != 0 (`avoid` empty or one per cell: e.g. cells outside
// the silhouettes) only in a round where no other cell is left to add. Returns the cells added.
size_t RepairPinches(const TetMesh& mesh, const std::vector<CellFace>& faces,
                     std::vector<uint8_t>* interior, const std::vector<uint8_t>& avoid = {});

// Settings of the final surface.
struct TetSurfaceOptions {
  int smoothing_iterations = 10;  // lambda|mu pairs (taubin_smoothing.h)
  double smoothing_lambda = 0.5;
  double smoothing_mu = -0.53;
  double max_vertex_shift = 0.0;  // metres per axis from the cells' corner
};

// The interior's boundary after RepairPinches (avoiding `avoid` cells), smoothed; the corners
// of `pinned` cells keep their places (a silhouette pixel whose ray crosses such a cell stays
// covered).
TriangleMesh ExtractTetSurface(const TetMesh& mesh, const std::vector<CellFace>& faces,
                               std::vector<uint8_t> interior, const TetSurfaceOptions& options,
                               const std::vector<int32_t>& pinned,
                               const std::vector<uint8_t>& avoid = {}, size_t* repaired = nullptr);

}  // namespace silnet::aggregator
