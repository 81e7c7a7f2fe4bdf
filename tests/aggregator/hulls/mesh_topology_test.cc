#include "aggregator/hulls/mesh_topology.h"

#include <gtest/gtest.h>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {
namespace {

// The boundary of the occupied voxels of a 6^3 grid where `fill(i, j, k)` is true.
template <typename Fill>
TriangleMesh VoxelSolid(Fill fill) {
  VoxelGrid grid = VoxelGrid::Empty(Eigen::Vector3d(0, 0, 1), 0.1, {6, 6, 6});
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k)
        grid.occupied[grid.Index(i, j, k)] = fill(i, j, k) ? 1 : 0;
  return ExtractBoundaryMesh(grid);
}

TEST(MeshTopologyTest, SeparateBlocksAndARingAreToldApart) {
  // A 4x4x2 ring (the middle 2x2 column empty: one through-hole) and a separate small cube.
  const TriangleMesh mesh = VoxelSolid([](int i, int j, int k) {
    const bool ring = i < 4 && j < 4 && k < 2 && !(i >= 1 && i <= 2 && j >= 1 && j <= 2);
    const bool cube = i == 5 && j == 5 && k == 5;
    return ring || cube;
  });
  const std::vector<MeshComponent> pieces = MeshComponents(mesh);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].genus, 1);
  EXPECT_EQ(pieces[0].euler_characteristic, 0);
  EXPECT_EQ(pieces[1].genus, 0);
  EXPECT_EQ(pieces[1].triangles, 12u);
  EXPECT_EQ(pieces[1].vertices, 8u);
  EXPECT_GT(pieces[0].triangles, pieces[1].triangles);
}

TEST(MeshTopologyTest, TwoHolesAreGenusTwoAndBadTrianglesAreIgnored) {
  // A 5x3x1 slab with two separate holes.
  TriangleMesh mesh = VoxelSolid([](int i, int j, int k) {
    return i < 5 && j < 3 && k == 0 && !(j == 1 && (i == 1 || i == 3));
  });
  mesh.triangles.push_back({0, 0, 1});
  mesh.triangles.push_back({0, 1, static_cast<int32_t>(mesh.vertices.size())});
  const std::vector<MeshComponent> pieces = MeshComponents(mesh);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].genus, 2);
  EXPECT_TRUE(MeshComponents(TriangleMesh{}).empty());
}

TEST(MeshTopologyTest, TrianglePiecesNameEachTrianglesPiece) {
  // Three separate cubes; then a bad triangle, which belongs to none.
  TriangleMesh mesh = VoxelSolid([](int i, int j, int k) {
    return (i == 0 && j == 0 && k == 0) || (i == 2 && j == 2 && k == 2) ||
           (i == 4 && j == 0 && k == 4);
  });
  mesh.triangles.push_back({0, 0, 1});
  size_t count = 0;
  const std::vector<int32_t> piece = TrianglePieces(mesh, &count);
  ASSERT_EQ(count, 3u);
  ASSERT_EQ(piece.size(), mesh.triangles.size());
  EXPECT_EQ(piece.back(), -1);
  std::vector<size_t> triangles(count, 0);
  for (size_t t = 0; t + 1 < piece.size(); ++t) {
    ASSERT_GE(piece[t], 0);
    ++triangles[static_cast<size_t>(piece[t])];
    // Triangles sharing a vertex share a piece.
    for (size_t u = 0; u < t; ++u)
      for (int32_t a : mesh.triangles[t])
        for (int32_t b : mesh.triangles[u])
          if (a == b) {
            EXPECT_EQ(piece[t], piece[u]);
          }
  }
  EXPECT_EQ(triangles, std::vector<size_t>(3, 12));
  // Numbered by their smallest vertex.
  std::vector<int32_t> smallest(count, static_cast<int32_t>(mesh.vertices.size()));
  for (size_t t = 0; t + 1 < piece.size(); ++t)
    for (int32_t v : mesh.triangles[t])
      smallest[static_cast<size_t>(piece[t])] =
          std::min(smallest[static_cast<size_t>(piece[t])], v);
  EXPECT_LT(smallest[0], smallest[1]);
  EXPECT_LT(smallest[1], smallest[2]);
}

}  // namespace
}  // namespace silnet::aggregator
