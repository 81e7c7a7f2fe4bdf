#pragma once
// A light copy of a triangle mesh for drawing in a browser: vertices clustered on a uniform
// grid until the mesh has at most a given number of triangles (vertex clustering, Rossignac
// and Borrel), with smooth vertex normals. For looking at only: the copy keeps the shape to
// within a grid cell but need not stay closed or manifold.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// Vertices with unit normals and triangles indexing them.
struct DisplayMesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;  // one per position, unit length (zero if isolated)
  std::vector<std::array<uint32_t, 3>> triangles;
  double cell = 0;  // clustering cell edge (0: the mesh was small enough as it was)
};

// `mesh` itself when it has at most `max_triangles` triangles, else its vertices merged per
// cell of the coarsest grid tried (cells growing by 1.25x from 1/2000 of the bounding box's
// diagonal) that brings it under `max_triangles`; triangles that collapse or turn over are
// dropped.
// Normals are the area-weighted means of the faces around each vertex.
DisplayMesh MakeDisplayMesh(const TriangleMesh& mesh, size_t max_triangles = 150000);

}  // namespace silnet::aggregator
