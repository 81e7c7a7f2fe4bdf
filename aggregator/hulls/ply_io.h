#pragma once
// Binary little-endian PLY files of triangle meshes: "vertex" elements with float x, y, z
// and "face" elements with a uchar-counted list of int vertex indices. The layout every
// mesh viewer (MeshLab, Blender, Open3D) reads.

#include <string>

#include "aggregator/hulls/triangle_mesh.h"

namespace silnet::aggregator {

// Writes `mesh` to `path`; vertex and index values are stored bit-exactly. Throws
// InputError if the file cannot be written.
void WritePlyMesh(const std::string& path, const TriangleMesh& mesh);

// Reads a binary little-endian PLY file with exactly the layout WritePlyMesh writes
// (vertex x y z float; face list uchar int, three indices per face). Throws InputError
// naming the problem for other layouts and for truncated or malformed files.
TriangleMesh ReadPlyMesh(const std::string& path);

}  // namespace silnet::aggregator
