#pragma once
// An indexed triangle mesh in world coordinates (metres). Triangles list their vertices
// counter-clockwise seen from outside, so normals (b - a) x (c - a) point outwards.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace silnet::aggregator {

// Vertices and triangles; triangle entries index `vertices`.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<int32_t, 3>> triangles;
};

}  // namespace silnet::aggregator
