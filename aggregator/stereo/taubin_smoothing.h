#pragma once
// Taubin's lambda|mu smoothing of a triangle mesh ("A Signal Processing Approach to Fair
// Surface Design", SIGGRAPH 1995): pairs of umbrella-operator Laplacian steps, one shrinking
// (lambda > 0), one inflating (mu < -lambda), which remove a lattice's staircase without
// shrinking the surface. Each vertex stays within its own box, so the smoothed surface keeps
// within a known distance of the one it came from. Moves vertices only: a closed manifold
// stays one.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// Each vertex's distinct neighbours along mesh edges, as offsets into one array (CSR):
// vertex i's are ids[begin[i]] .. ids[begin[i + 1] - 1].
struct VertexNeighbours {
  std::vector<size_t> begin;  // vertices + 1 entries
  std::vector<int32_t> ids;
};

// The neighbours of every vertex of `mesh`.
VertexNeighbours FindVertexNeighbours(const TriangleMesh& mesh);

// Smooths `mesh` in place: `iterations` lambda|mu pairs, vertex i clamped to [lo[i], hi[i]]
// after every step (lo, hi as long as the vertices; CheckError otherwise).
void TaubinSmooth(TriangleMesh* mesh, int iterations, double lambda, double mu,
                  const std::vector<Eigen::Vector3f>& lo, const std::vector<Eigen::Vector3f>& hi);
// The same with the mesh's neighbours (FindVertexNeighbours) already at hand.
void TaubinSmooth(TriangleMesh* mesh, const VertexNeighbours& neighbours, int iterations,
                  double lambda, double mu, const std::vector<Eigen::Vector3f>& lo,
                  const std::vector<Eigen::Vector3f>& hi);

}  // namespace silnet::aggregator
