#pragma once
// Rays walked through a conforming tetrahedral mesh from cell to adjacent cell (thesis 7.3.3:
// "walking along the ray within the tetrahedral mesh and performing ray-triangle
// intersections"): each cell the ray crosses is visited once, in order, whatever its size,
// at the cost of one exit test per cell instead of a point location per sample.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/stereo/bcc_lattice.h"
#include "aggregator/stereo/tet_surface.h"

namespace silnet::aggregator {

// The cells adjacent to each cell of a mesh, and walks of rays through them.
class TetRayWalker {
 public:
  // Cells in a row a walk may visit without getting further along its ray.
  static constexpr size_t kMaxStanding = 64;

  // `faces` from SortedCellFaces(mesh). The mesh must outlive the walker.
  TetRayWalker(const TetMesh& mesh, const std::vector<CellFace>& faces);

  // The cell across cell t's face opposite its corner o (0..3), or -1 on the mesh's boundary.
  int32_t Across(int32_t t, int o) const { return across_[4 * static_cast<size_t>(t) + o]; }

  // Calls visit(cell, entry, exit) for the cells the ray origin + s * direction (s >= 0;
  // direction not zero) crosses, in order, with the parameters s where it enters and leaves
  // each, starting with `start`, a cell that holds the origin (entered at 0), until visit
  // returns false, the ray leaves the mesh or `max_cells` cells were visited. A ray through
  // an edge or a vertex goes on through one of the cells around it; one that makes no
  // progress through kMaxStanding cells in a row (rounding round an edge) stops. Returns the
  // cells visited.
  template <typename Visit>
  size_t Walk(int32_t start, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              Visit&& visit, size_t max_cells = size_t{1} << 20) const {
    int32_t cell = start, previous = -1;
    double s = 0.0;
    size_t visited = 0, standing = 0;  // cells in a row without progress along the ray
    while (cell >= 0 && visited < max_cells && standing < kMaxStanding) {
      ++visited;
      const double entry = s;
      const int32_t next = Exit(cell, previous, origin, direction, &s);
      if (!visit(cell, entry, s)) break;
      standing = s > entry ? 0 : standing + 1;
      previous = cell;
      cell = next;
    }
    return visited;
  }

 private:
  // The cell the ray leaves `cell` into, at the smallest parameter >= *s among the faces it
  // leaves through (not back into `previous` unless nothing else is left); *s updated. -1 if
  // that face is on the mesh's boundary.
  int32_t Exit(int32_t cell, int32_t previous, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction, double* s) const;

  const TetMesh& mesh_;
  std::vector<int32_t> across_;  // 4 per cell
};

}  // namespace silnet::aggregator
