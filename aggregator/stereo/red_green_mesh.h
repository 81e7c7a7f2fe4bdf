#pragma once
// Red-green refinement of a tetrahedral mesh (thesis 7.3.1; the scheme of Molino, Bridson and
// Fedkiw, "Tetrahedral mesh generation for deformable bodies", 2003). Red refinement cuts a
// tetrahedron into eight by its six edge midpoints, the inner octahedron along its shortest
// diagonal, so the children of a BCC tetrahedron are congruent to it at half the size. The
// refined tetrahedra form a tree whose leaves are the red cells. A leaf whose edges a finer
// neighbour split is, in the conforming mesh, cut into its green form: one split edge 1:2,
// two split edges 1:3 (on one face) or 1:4 (opposite), the three edges of one face 1:4.
// Green cells are never refined: a leaf with any other pattern of split edges, or whose green
// form would have a split edge, is red-refined too (the closure), so the conforming mesh has
// no hanging vertex.

#include <absl/container/flat_hash_map.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "aggregator/stereo/bcc_lattice.h"

namespace silnet::aggregator {

// The conforming mesh of a RedGreenMesh at one moment.
struct ConformingTetMesh {
  TetMesh mesh;                // the red leaves and the green cells, positively oriented
  std::vector<int32_t> leaf;   // per tetrahedron: the red leaf it is or was cut from
  std::vector<uint8_t> green;  // per tetrahedron: 1 if a green cell
};

// A tetrahedral mesh refined red-green.
class RedGreenMesh {
 public:
  // The base mesh's tetrahedra are the roots (level 0); they must be conforming.
  explicit RedGreenMesh(TetMesh base);

  // Base vertices first, then edge midpoints in the order they were made.
  const std::vector<Eigen::Vector3d>& Vertices() const { return vertices_; }
  // Every tetrahedron of the tree, refined or not (ids are indices).
  size_t TetrahedronCount() const { return tets_.size(); }
  // The corners (vertex ids) of tetrahedron `tet`.
  const Tetrahedron& Corners(int32_t tet) const { return tets_[tet].v; }
  int Level(int32_t tet) const { return tets_[tet].level; }
  bool IsLeaf(int32_t tet) const { return tets_[tet].first_child < 0; }
  // The leaves, in id order.
  std::vector<int32_t> Leaves() const;
  size_t LeafCount() const { return leaf_count_; }

  // Red-refines the given leaves (ids that are no longer leaves are skipped), then closes the
  // mesh as above. Returns how many leaves were refined, the closure's included.
  size_t Refine(const std::vector<int32_t>& leaves);

  // The conforming mesh: each leaf as it is, or cut into its green form.
  ConformingTetMesh Conform() const;

  // The midpoint vertex of edge (a, b), or -1 if the edge is not split.
  int32_t Midpoint(int32_t a, int32_t b) const;

 private:
  struct Node {
    Tetrahedron v;
    int32_t first_child = -1;  // its eight children are consecutive
    int32_t level = 0;
  };

  int32_t MakeMidpoint(int32_t a, int32_t b);
  void RedRefine(int32_t tet);
  // The leaf's green form, appended to `out` (unoriented); false if it has none.
  bool GreenForm(int32_t tet, std::vector<Tetrahedron>* out) const;
  void AddIncidence(int32_t tet);
  void RemoveIncidence(int32_t tet);

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Node> tets_;
  absl::flat_hash_map<uint64_t, int32_t> midpoints_;
  std::vector<std::vector<int32_t>> incident_leaves_;  // per vertex
  std::vector<std::array<int32_t, 2>> parent_edge_;    // per vertex: the edge it halves, or -1
  size_t leaf_count_ = 0;
};

}  // namespace silnet::aggregator
