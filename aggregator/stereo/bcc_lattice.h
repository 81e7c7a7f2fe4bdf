#pragma once
// The base mesh of the adaptive stereo (thesis 7.3.1): a body-centred cubic (BCC) lattice
// split into tetrahedra. Its vertices are the nodes of a cubic grid of spacing h and the
// centres of the grid's cubes (two interlaced cubic lattices); every face of the grid, with
// the centres of the two cubes on either side of it, bounds an octahedron cut into four
// tetrahedra along the line between the centres. All tetrahedra are congruent (two edges of
// length h, four of sqrt(3)/2 h), about 12 per cube, and red refinement (red_green_mesh.h)
// keeps them so.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// Four vertex indices, positively oriented: (v1 - v0) . ((v2 - v0) x (v3 - v0)) > 0.
using Tetrahedron = std::array<int32_t, 4>;

// Vertices and tetrahedra of a conforming mesh: any two tetrahedra meet in a shared face, a
// shared edge, a shared vertex or not at all.
struct TetMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Tetrahedron> tetrahedra;
};

// Six times the signed volume of (a, b, c, d): positive when the order is positive.
double SignedVolume6(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);

// The tetrahedron with two vertices swapped if needed so its order is positive.
Tetrahedron PositivelyOriented(const Tetrahedron& tet,
                               const std::vector<Eigen::Vector3d>& vertices);

// The BCC tetrahedra covering `box` (its sides rounded up to whole cubes of `spacing`,
// anchored at box.min()): the grid nodes first, x fastest, then the cube centres, including
// one layer of centres outside the box so the faces on its sides have tetrahedra too. The
// union of the tetrahedra holds the rounded box. CheckError if the box is empty, the spacing
// not positive or the lattice over 2^31 vertices.
TetMesh BuildBccLattice(const WorldBox& box, double spacing);

}  // namespace silnet::aggregator
